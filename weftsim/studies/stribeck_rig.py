"""A published Stribeck test of plain journal bearings against ``weftsim bearing`` (docs/lubricated-joint.md).

A rig file (``tests/data/stribeck_sander2016.toml``: Sander, Allmaier, Priebsch, Witt and Skiadas, Tribol. Int.
96, 2016) names the rig's bearings, each by the scene keys of its joint (``[bearings.NAME.keys]``, keys of
``[joint_e]`` in file units) and the oil and surfaces they share (``[lubrication]``, keys of
``[joint_e.lubrication]``), how many of each turn on the shaft and which share of the rig's load each carries,
and the shaft's input torque measured against speed at each load.  Every bearing becomes the bundled loom
scene's joint E with those keys (:func:`weftsim.input.scene.load_scene`: the keys are checked as a scene's),
and each operating point is the one ``weftsim bearing SCENE --load-kn F --journal-rpm N`` evaluates
(:func:`weftsim.joint.bearing.operating_point`, the steady kernel of the transient engines); the rig's torque
is the sum over its bearings.  An optional ``[elastic]`` table holds further ``[joint_e.lubrication]`` keys that
turn the elastic film on (:func:`with_elastic`).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from weftsim.errors import SceneError

if TYPE_CHECKING:
    from weftsim.input.params import ClearanceJoint

BASE_SCENE = "loom"  # the bundled scene whose joint E takes each bearing's keys


@dataclass(frozen=True)
class RigBearing:
    """One kind of bearing on the rig's shaft: ``count`` of them, each carrying ``load_share`` of the load."""

    name: str
    joint: ClearanceJoint  # lubricated
    count: int
    load_share: float


@dataclass(frozen=True)
class Rig:
    """A Stribeck rig: its bearings, and per load (N) the measured (rpm, torque N m) and the speed of least
    torque."""

    source: str
    bearings: tuple[RigBearing, ...]
    loads: tuple[dict, ...]
    elastic: tuple[RigBearing, ...] = ()  # the bearings with the rig's [elastic] keys as well (empty: none given)


def load_rig(path: str | Path) -> Rig:
    """The rig of file ``path`` (module docstring); a missing or bad key is one :class:`SceneError` line."""
    from weftsim.input.scene import load_scene

    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
        shared = {f"joint_e.lubrication.{key}": value for key, value in data["lubrication"].items()}
        extra = {f"joint_e.lubrication.{key}": value for key, value in data.get("elastic", {}).items()}
        bearings, elastic = [], []
        for name, table in data["bearings"].items():
            keys = {f"joint_e.{key}": value for key, value in table["keys"].items()}

            def bearing(more: dict, name=name, table=table, keys=keys) -> RigBearing:
                scene = load_scene(BASE_SCENE, overrides={**keys, **shared, **more},
                                   overrides_from=f"rig file {path}, [bearings.{name}]")
                return RigBearing(name, scene.joint, int(table["count"]), float(table["load_share"]))

            bearings.append(bearing({}))
            if extra:
                elastic.append(bearing(extra))
        loads = tuple({"load_n": 1e3 * float(case["load_kn"]), "rpm": [float(n) for n in case["rpm"]],
                       "torque_nm": [float(m) for m in case["torque_nm"]], "minimum_rpm": float(case["minimum_rpm"]),
                       **({"min_film_rpm": case["min_film_rpm"], "min_film_um": case["min_film_um"]}
                          if "min_film_rpm" in case else {})} for case in data["loads"])
        return Rig(str(data["source"]), tuple(bearings), loads, tuple(elastic))
    except SceneError:
        raise  # a bearing's scene key, named with the file by load_scene
    except KeyError as exc:
        raise SceneError(f"rig file {path}: missing table or key {exc} "
                         "(see tests/data/stribeck_sander2016.toml)") from None
    except (OSError, tomllib.TOMLDecodeError, TypeError, ValueError) as exc:
        raise SceneError(f"rig file {path}: {exc}") from None


def with_elastic(rig: Rig) -> Rig:
    """The rig with its ``[elastic]`` keys (the elastic film of :mod:`weftsim.joint.ehl`); refused if it has none."""
    if not rig.elastic:
        raise SceneError("the rig file has no [elastic] table (keys of [joint_e.lubrication] for the elastic film)")
    return replace(rig, bearings=rig.elastic, elastic=())


def with_floor(rig: Rig, floor: float) -> Rig:
    """The rig with every bearing's ``film_floor_ratio`` set to ``floor`` (the numerical guard of the film)."""
    bearings = []
    for b in rig.bearings:
        lub = b.joint.lubrication
        assert lub is not None  # load_rig gives every bearing the rig's [lubrication]
        bearings.append(replace(b, joint=replace(b.joint, lubrication=replace(lub, film_floor_ratio=floor))))
    return replace(rig, bearings=tuple(bearings))


def rig_point(rig: Rig, load: float, rpm: float) -> dict:
    """The rig at ``load`` (N) and shaft speed ``rpm``: ``torque_nm`` (the sum over its bearings) and per bearing
    its :func:`weftsim.joint.bearing.operating_point` dict (``bearings``)."""
    from weftsim.joint.bearing import operating_point

    omega = rpm * math.pi / 30.0
    parts = {b.name: operating_point(b.joint, b.load_share * load, omega) for b in rig.bearings}
    torque = sum(b.count * parts[b.name]["friction_torque_nm"] for b in rig.bearings)
    return {"load_n": load, "rpm": rpm, "torque_nm": torque, "bearings": parts}


def comparison(rig: Rig) -> list[dict]:
    """Per load: the measured and weftsim's torques at the measured speeds, their ratios, and the speeds of least
    torque (measured: the published one; weftsim: the least of its values at the measured speeds)."""
    out = []
    for case in rig.loads:
        points = [rig_point(rig, case["load_n"], n) for n in case["rpm"]]
        torques = [p["torque_nm"] for p in points]
        least = min(range(len(torques)), key=torques.__getitem__)
        out.append({**case, "points": points, "weftsim_nm": torques,
                    "ratio": [t / m for t, m in zip(torques, case["torque_nm"])],
                    "weftsim_minimum_rpm": case["rpm"][least]})
    return out
