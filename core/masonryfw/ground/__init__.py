"""The ground that moves: settlement profiles along a wall (greenfield troughs, tilts, measured rates), the
ground in plan under a building (a tunnel's trough and face at an angle), and the assessment's stages 1 and 2
(greenfield strains, the limiting tensile strain method, damage categories of Burland).

Data comes in as a spec's ``[settlement]`` table and a wall's extent and leaves as a profile (motion per unit
of settlement at any point) that builders put on a model and results read back.
"""
