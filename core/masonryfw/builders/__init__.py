"""From a spec to a model dataset: the one ordered table of spec kinds (``kinds.SPEC_KINDS``: a
building, a 3D drawing, a wall laid in its outline, a drawn wall, a wall of rectangular units), each kind's
builder, bonds, supports and the paper's support loads, the ground put under a model, plausibility warnings, and
``sources`` (what a name on the command line stands for, and the files it reads).

Data flows spec -> kind -> builder -> arrays -> ``format`` model; ``build`` and ``load_spec`` walk the table.
"""
