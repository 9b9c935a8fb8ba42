"""The conformance suite every masonryfw solver passes (``from masonryfw.testing import SolverConformance``).

It checks that the result passes :func:`masonryfw.check` with the schema's names, dims and units, that every
variable it adds has ``units`` and a ``long_name``, that its key numbers, headline and scalar results are finite
numbers, that progress is reported in [0, 1], that an interruption (``KeyboardInterrupt`` raised from the progress
callback) either propagates or returns a result marked ``interrupted = 1``, that it solves the dimensions it
declares, that its estimate is finite, that every declared option's default obeys its own rules and that values
breaking them are refused, and that the solve depends neither on the order of the blocks nor on mm against m (to a
relative ``invariance_tolerance`` of the key numbers). Needs pytest.
"""
from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import pytest

from .api import estimate, solve
from .contract.registry import get_solver
from .format.checks import check
from .format.model3d import twin
from .format.schema import load_schema
from .results.summary import headline_text, key_numbers
from .runtime.errors import PluginError, SolveError
from .testing import permuted, scaled, small_settlement_wall

if TYPE_CHECKING:  # annotations only
    import xarray as xr


def _refuse_constant(name: str):
    raise AssertionError(f"{name} in a JSON field")


class SolverConformance:
    """Tests every masonryfw solver passes; subclass as ``TestMySolver`` and set ``solver`` (module docstring)."""

    solver: ClassVar[str] = ""
    options: ClassVar[Mapping[str, Any]] = {}
    #: Relative tolerance of the key numbers under block reordering and mm against m.
    invariance_tolerance: ClassVar[float] = 1e-6

    @staticmethod
    def conformance_model() -> xr.Dataset:
        """The model the suite solves (override for a solver that needs another)."""
        return small_settlement_wall()

    @pytest.fixture(scope="class")
    @classmethod
    def solved(cls) -> tuple[xr.Dataset, list]:
        """One solve of the conformance model, with every progress call it made."""
        calls: list[tuple[float, str]] = []
        result = solve(cls.conformance_model(), cls.solver, cls.options,
                       progress=lambda fraction, message="": calls.append((fraction, message)))
        return result, calls

    def test_the_result_passes_check(self, solved):
        result, _ = solved
        assert check(result) == []
        assert result.attrs["solver"] == self.solver

    def test_every_added_variable_has_units_and_a_long_name(self, solved):
        result, _ = solved
        model_variables = set(load_schema("model")["variables"])
        for name, variable in result.variables.items():
            if name in model_variables or name in result.coords:
                continue
            assert "units" in variable.attrs, f"{self.solver}: variable {name} has no units"
            assert variable.attrs.get("long_name"), f"{self.solver}: variable {name} has no long_name"

    def test_every_key_number_and_headline_is_finite(self, solved):
        """What a user reads is a number: no NaN or inf among the key numbers (what ``solve`` prints and
        ``compare --json`` writes), the headline or the scalar results."""
        result, _ = solved
        numbers = key_numbers(result)
        bad = [f"{n.name} = {n.value}" for n in numbers if not math.isfinite(n.value)]
        assert not bad, f"{self.solver}: key numbers that are not finite: {', '.join(bad)}"
        json.loads(json.dumps({n.name: n.value for n in numbers}), parse_constant=_refuse_constant)
        text = headline_text(result) or ""
        assert not re.search(r"\b(nan|inf)\b", text, re.IGNORECASE), f"{self.solver}: headline {text!r}"
        for name, variable in result.data_vars.items():
            if variable.ndim == 0 and np.issubdtype(variable.dtype, np.floating):
                assert np.isfinite(variable.values), f"{self.solver}: scalar {name} = {variable.values}"

    def test_progress_is_reported_between_0_and_1(self, solved):
        _, calls = solved
        assert calls, f"{self.solver} never called progress"
        assert all(0.0 <= fraction <= 1.0 for fraction, _ in calls)
        assert all(isinstance(message, str) for _, message in calls)

    def test_an_interruption_is_honoured(self):
        """A KeyboardInterrupt raised from the first, a middle and the last progress call. The calls are counted
        on a second solve in this process (the first here, whatever ran before): a first one may report one-time
        work (a compilation, a cache loaded) once, so which test ran first must not matter."""
        counted: list[float] = []
        for count in (lambda fraction, message="": None, lambda fraction, message="": counted.append(fraction)):
            solve(self.conformance_model(), self.solver, self.options, progress=count)
        for at in sorted({1, len(counted) // 2 + 1, len(counted)}):
            seen: list[float] = []

            def interrupt(fraction, message="", at=at, seen=seen):
                seen.append(fraction)
                if len(seen) == at:
                    raise KeyboardInterrupt

            try:
                result = solve(self.conformance_model(), self.solver, self.options, progress=interrupt)
            except KeyboardInterrupt:
                continue  # nothing to keep: propagated
            assert len(seen) >= at, (f"{self.solver} made {len(seen)} progress calls where the same solve before it "
                                     f"made {len(counted)}: the interruption was not raised")
            assert int(result.attrs.get("interrupted", 0)) == 1, (
                f"{self.solver} swallowed a KeyboardInterrupt at progress call {at} and returned as if complete")
            assert check(result) == []

    def test_the_dimensions_it_declares_are_the_ones_it_solves(self, solved):
        """2D, 3D or both (``Solver.spaces``): the conformance model stood one block thick in 3D
        (:func:`masonryfw.format.model3d.twin`) is solved and checked when 3D is declared (or, for options the solver
        does not support in 3D, refused with a SolveError that says 3D), refused before the run (a SolveError
        naming the solver) when it is not."""
        spaces = get_solver(self.solver).spaces
        assert spaces and set(spaces) <= {2, 3}, f"{self.solver} declares spaces {spaces}: 2, 3 or both"
        in_3d = twin(self.conformance_model())
        if 3 in spaces:
            try:
                result = solve(in_3d, self.solver, self.options)
            except SolveError as refusal:
                assert "3D" in str(refusal), f"{self.solver} declares 3D but refused without saying why: {refusal}"
                return
            assert check(result) == []
        else:
            with pytest.raises(SolveError, match=f"solver {self.solver} solves 2D models"):
                solve(in_3d, self.solver, self.options)

    def test_an_estimate_is_finite_and_positive(self):
        expected = estimate(self.conformance_model(), self.solver, self.options)
        if expected is None:
            return  # the hook is optional
        assert 0 < expected.seconds < float("inf") and 0 < expected.memory < float("inf"), expected
        assert expected.basis, f"{self.solver}: an estimate says what it is based on"

    def test_every_default_obeys_its_rules(self):
        for option in get_solver(self.solver).options:
            if not option.auto:
                assert option.parse(option.default) == option.default, option.name

    def test_values_breaking_the_rules_are_refused(self):
        record = get_solver(self.solver)
        with pytest.raises(PluginError, match="unknown option"):
            solve(self.conformance_model(), self.solver, {"no_such_option": 1})
        for option in record.options:
            for value in _breaking_values(option):
                with pytest.raises(PluginError, match=option.name):
                    solve(self.conformance_model(), self.solver, {**self.options, option.name: value})

    def test_the_order_of_the_blocks_does_not_matter(self, solved):
        result, _ = solved
        model = self.conformance_model()
        rng = np.random.default_rng(7)
        shuffled = permuted(model, rng.permutation(model.sizes["block"]), rng.permutation(model.sizes["interface"]))
        _assert_same_numbers(result, solve(shuffled, self.solver, self.options), self.invariance_tolerance)

    def test_millimetres_give_the_metre_result(self, solved):
        result, _ = solved
        again = solve(scaled(self.conformance_model(), 1e3), self.solver, self.options)
        _assert_same_numbers(result, again, self.invariance_tolerance)


def _breaking_values(option) -> list:
    values: list[Any] = []
    if option.type in (int, float):
        values.append("not-a-number")
        for bound, step in ((option.above, 0.0), (option.at_least, -1.0), (option.below, 0.0), (option.at_most, 1.0)):
            if bound is not None:
                values.append(option.type(bound + step) if option.type is float else int(math.floor(bound + step)))
    if option.choices is not None:
        values.append("no-such-choice")
    return values


#: Key numbers compared by the invariance tests: forces and multipliers (settlements at a minimum or
#: a plateau's start move between records on a flat curve, and macro-block counts with noise).
COMPARED_NUMBERS = ("alpha", "collapse_reaction", "dead_reaction", "minimum_reaction", "plateau_reaction")


def _assert_same_numbers(a: xr.Dataset, b: xr.Dataset, tolerance: float) -> None:
    """The headline forces and multipliers of two results agree to ``tolerance`` (relative)."""
    first = {n.name: n.value for n in key_numbers(a) if n.name in COMPARED_NUMBERS}
    second = {n.name: n.value for n in key_numbers(b) if n.name in COMPARED_NUMBERS}
    assert set(first) == set(second)
    for name, value in first.items():
        assert second[name] == pytest.approx(value, rel=tolerance, abs=1e-12), name
