"""Every built-in solver, and the example plugin, passes the conformance kit a third-party author would run."""
from __future__ import annotations

from masonryfw.testing import SolverConformance


class TestLa(SolverConformance):
    solver = "la"
    invariance_tolerance = 1e-7


class TestLaNonassociative(SolverConformance):
    solver = "la"
    options = {"flow": "nonassociative"}
    invariance_tolerance = 1e-6  # the fixed point to its flow_tolerance (docs/la.md); measured spread 2e-8


class TestFdem(SolverConformance):
    solver = "fdem"
    # explicit frictional dynamics: another order of summation (blocks renumbered) or the
    # same wall in mm changes the round-off, which the path-dependent sliding amplifies
    invariance_tolerance = 0.02


class TestJmm(SolverConformance):
    solver = "jmm"
    options = {"max_steps": 8}
    invariance_tolerance = 1e-4


class TestJmmLimit(SolverConformance):
    solver = "jmm-limit"
    invariance_tolerance = 1e-6


class TestStatics(SolverConformance):
    solver = "statics"


class TestLaIncremental(SolverConformance):
    solver = "la-incremental"
    options = {"settlement": 0.01}
    invariance_tolerance = 1e-6
