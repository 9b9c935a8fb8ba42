"""What results mean, one definition for every solver and the compare plugin: relative motion at
joints, interface states, the crack indicator and macro-blocks (``semantics`` in 2D, ``semantics3d`` in 3D),
crack widths and damage categories (``damage``), key numbers and tables (``summary``), a model described in words.

Data comes in as a result dataset (a model plus a solver's block motions) and leaves as labelled arrays and
text that plots, reports and comparisons show.
"""
