"""The kinds of spec, in one ordered table: what each claims, how it builds, how it is checked, which files it reads.

``build``, ``load_spec`` and ``input_files`` walk :data:`SPEC_KINDS` and take the first kind that claims a spec,
as xarray's ``guess_engine`` asks each backend ``guess_can_open``; a new kind of spec is a new row, and the three
cannot disagree about a spec (an outline spec's DXF and a 3D drawing's OBJ were not seen as inputs, so ``-o``
onto them was refused only after the build).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..format.model import checked_model
from ..format.model3d import twin
from ..readers.spec import read_spec
from ..runtime.errors import MasonryError, SpecError
from .building import build_building, read_building
from .drawn import build_drawn, parse_drawn_spec, resolved_drawing
from .drawn3d import build_drawn_3d, mesh_path
from .outlined import build_outlined, drawing_paths, is_outlined
from .parametric import build_parametric, parse_spec
from .plausibility import warn_implausible

if TYPE_CHECKING:  # annotations only
    import xarray as xr


@dataclass(frozen=True)
class SpecKind:
    """One kind of spec. ``claims(spec)`` says whether a spec dict is of this kind; ``builds(spec, text, base_dir,
    validate)`` makes its model; ``checks(spec, base_dir)`` validates it without laying blocks where the kind can
    (a building is only read) and returns it with its files' paths made absolute; ``reads(spec, base_dir)`` names
    the files besides the spec that building it reads; ``three_d``: the kind is 3D only (the others are 2D and
    ``space = 3`` builds their twin)."""

    name: str
    claims: Callable[[dict], bool]
    builds: Callable[[dict, str, Path | None, bool], xr.Dataset]
    checks: Callable[[dict, Path | None], dict]
    reads: Callable[[dict, Path | None], list[Path]]
    three_d: bool = False


def _geometry(spec: dict) -> dict | None:
    geometry = spec.get("geometry") if isinstance(spec, dict) else None
    return geometry if isinstance(geometry, dict) else None


def _nothing_read(spec: dict, base_dir: Path | None) -> list[Path]:
    return []


def _with_paths(spec: dict, paths: dict[str, Path]) -> dict:
    """``spec`` with these ``geometry`` keys set to their absolute paths."""
    if not paths:
        return spec
    return {**spec, "geometry": {**spec["geometry"], **{k: str(p.resolve()) for k, p in paths.items()}}}


# --------------------------------------------------------------------------- the rows


def _building_checked(spec: dict, base_dir: Path | None) -> dict:
    read_building(spec)
    return spec


BUILDING = SpecKind("building", lambda spec: isinstance(spec, dict) and "building" in spec,
                    lambda spec, text, base_dir, validate: build_building(spec, text), _building_checked,
                    _nothing_read, three_d=True)


def _mesh_checked(spec: dict, base_dir: Path | None) -> dict:
    spec = _with_paths(spec, {"mesh": mesh_path(spec, base_dir)})
    build_drawn_3d(spec, "", None)
    return spec


DRAWN_3D = SpecKind("drawing in 3D", lambda spec: "mesh" in (_geometry(spec) or {}),
                    lambda spec, text, base_dir, validate: build_drawn_3d(spec, text, base_dir), _mesh_checked,
                    lambda spec, base_dir: [mesh_path(spec, base_dir)], three_d=True)


OUTLINED = SpecKind("wall laid in its outline", is_outlined, build_outlined,
                    lambda spec, base_dir: _with_paths(spec, drawing_paths(spec, base_dir)),
                    lambda spec, base_dir: list(drawing_paths(spec, base_dir).values()))


def _drawing(spec: dict, base_dir: Path | None) -> tuple[str, Path]:
    drawn = parse_drawn_spec(spec)
    return drawn.drawing_key.split(".")[1], resolved_drawing(drawn, base_dir)


DRAWN = SpecKind("drawn wall", lambda spec: _geometry(spec) is not None, build_drawn,
                 lambda spec, base_dir: _with_paths(spec, dict([_drawing(spec, base_dir)])),
                 lambda spec, base_dir: [_drawing(spec, base_dir)[1]])


def _parametric_checked(spec: dict, base_dir: Path | None) -> dict:
    parse_spec(spec)
    return spec


PARAMETRIC = SpecKind("wall of rectangular units", lambda spec: isinstance(spec, dict),
                      lambda spec, text, base_dir, validate: build_parametric(spec, text, validate),
                      _parametric_checked, _nothing_read)

#: Every kind of spec, in the order they are asked: the first that claims a spec builds it.
SPEC_KINDS: tuple[SpecKind, ...] = (BUILDING, DRAWN_3D, OUTLINED, DRAWN, PARAMETRIC)


def spec_kind(spec: dict) -> SpecKind:
    """The kind of ``spec`` (a dict): the first of :data:`SPEC_KINDS` that claims it."""
    return next(kind for kind in SPEC_KINDS if kind.claims(spec))


def files_read(spec: dict, base_dir: Path | None) -> list[Path]:
    """The files besides the spec that building it reads (its drawing); none for a spec that cannot be read, which
    the build refuses with its message."""
    try:
        return spec_kind(spec).reads(spec, base_dir)
    except MasonryError:
        return []


# --------------------------------------------------------------------------- what walks the table


def build(spec, *, validate: bool = True) -> xr.Dataset:
    """Build the model dataset of a spec (a dict, a path, a Traversable or TOML text).

    The spec goes to the first of :data:`SPEC_KINDS` that claims it: a ``[building]`` (:mod:`masonryfw.builders.building`),
    a 3D drawing (``geometry.mesh``, :mod:`masonryfw.builders.drawn3d`), a wall laid in its outline (a drawing's
    ``outline_layer``, a gable, shaped openings, an English or Flemish bond, a height that is not whole courses:
    :mod:`masonryfw.builders.outlined`), a drawn wall (any other ``[geometry]``: :mod:`masonryfw.builders.drawn`; its drawing's
    path is relative to the spec file, else to the working folder) or a wall of rectangular units
    (:mod:`masonryfw.builders.parametric`). ``space = 3`` builds a 2D kind's wall one block thick in 3D
    (:func:`masonryfw.format.model3d.twin`). Raises :class:`SpecError` naming the key at fault. The model is returned
    checked (:func:`masonryfw.checked_model`), unless ``validate`` is False. Values outside the range of real
    masonry give a :class:`masonryfw.PlausibilityWarning` each (:mod:`masonryfw.builders.plausibility`).
    """
    spec_dict, text, base_dir = read_spec(spec)
    space = spec_dict.get("space", 2)
    if space not in (2, 3) or isinstance(space, bool):
        raise SpecError(f"space: must be 2 (the wall in its plane) or 3 (the wall one block thick in 3D), not {space!r}")
    kind = spec_kind(spec_dict)
    model = kind.builds(spec_dict, text, base_dir, validate and not kind.three_d)
    warn_implausible(model)
    if kind.three_d or space == 3:
        model = model if kind.three_d else twin(model)
        return checked_model(model, repr(model.attrs["title"])) if validate else model
    return model


def load_spec(path_or_text) -> dict:
    """Read and validate a spec: a path (str or PathLike or Traversable) or the TOML text itself.

    Returns the spec as a plain dict (as written, except that a drawing's path is made absolute), ready to be
    modified (e.g. by a parameter sweep) and passed to :func:`build`. A building is read and checked, not laid.
    """
    spec, _, base_dir = read_spec(path_or_text)
    return spec_kind(spec).checks(spec, base_dir)


#: What a wall read by :func:`load_wall` stands on when its spec gives no supports and no profile: every
#: support block moving (a tilt so gentle and wide that nothing is still), for a command that makes its own
#: ground from the wall's (``masonryfw diagnose``).
STAND_IN_GROUND = {"settlement": {"profile": "linear", "start": -1.0e6, "end": 1.0e6},
                   "loading": {"type": "settlement"}}


def load_wall(path_or_text) -> dict:
    """Read and validate a spec for its wall alone: its ``[supports.*]``, ``[settlement]`` and ``[loading]`` may
    be left out (:data:`STAND_IN_GROUND` stands in for them; a command that reads walls this way sets their
    supports aside and makes its own ground)."""
    spec, _, base_dir = read_spec(path_or_text)
    kind = spec_kind(spec)
    if kind.three_d:
        raise SpecError(f"the spec is 3D (a {kind.name}); a wall alone is read in 2D: masonryfw diagnose handles 2D "
                        "walls (a building's walls: masonryfw solve and capacity)")
    if "supports" not in spec and "settlement" not in spec:
        spec = {**spec, **STAND_IN_GROUND}
    return kind.checks({**spec, "loading": spec.get("loading", STAND_IN_GROUND["loading"])}, base_dir)
