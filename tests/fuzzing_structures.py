"""Generated URDFs and damaged trajectory logs, with an oracle that knows their defects.

Shared, like ``fuzzing.py`` (whose choosers and :func:`~fuzzing.classify` it uses), by
``tests/io/test_fuzz_readers.py`` (hypothesis draws the cases) and ``benchmarks/fuzz_readers.py``
(a seeded generator draws them, longer, and counts outcomes). The cases are built from a
structure, not by flipping bytes, so the oracle knows which must fail:

- **URDF**: a random tree of 1-7 links (revolute, continuous, prismatic and fixed joints,
  masses, centres of mass, origins, axes), then graph defects (a cycle beside the tree, a
  self-loop, a second parent, a missing link, a second root, a link or joint defined twice,
  a joint into the root), file defects (a DOCTYPE with an entity, a declared encoding not read
  or contradicting the bytes), numbers refused in an attribute read (``1e308``, ``0_1``,
  ``nan``, ``0x10``, a mass of ``1e-320`` kg, ...) and changes that keep the document
  (UTF-8 with a BOM, UTF-16 with or without one, UTF-32, ISO-8859-1 declared, odd but valid
  numbers such as ``1e-320`` m or ``+.5``). Read with :func:`fricid.io.urdf.read_urdf`, then
  eq. 7 of one rotating joint. A case with a defect must end in a clean error; a valid result
  must be finite, carry the mass of the links the structure puts downstream of the joint,
  stay within ``g m`` times the geometry's extent, and, for a change that keeps the document,
  equal the UTF-8 document's result exactly.
- **Trajectory**: the virtual joint's 2 s multi-sine at 1 kHz (J = 0.01 kg m^2, LuGre truth
  tau_c = 0.5 N m, sigma_2 = 0.2 N m s/rad: ``fricid simulate --trajectory multisine
  --duration 2``) damaged by holes (the clock jumps: every later stamp late), stamps moved or
  repeated, rows dropped (the stamps stay true), jittered stamps, a slower stretch, the
  current stuck over the whole log or a stretch; written as a CSV log and fitted
  (``read_rawlog``, then ``fit_trajectory(..., "stribeck")``). A hole or a loss of rows over
  five times the median step (``fricid.samples.HOLE_FACTOR``), a stamp out of order or the
  current stuck in every row must end in a clean error; a valid result must give the inertia
  and the Coulomb and viscous levels within a factor :data:`ABSURD` of the truth.

  Not generated: a clock jump under five median steps. The time column alone cannot tell it
  from lost rows (which change nothing: four lost rows kept the inertia within 1 %), yet it
  changes the answer (measured: a 0.5 ms jump at a fast moment moved the inertia by 35 %);
  catching it needs the velocity column's agreement with the position, which a drive's
  filtered velocity estimate does not give.
"""

from __future__ import annotations

import math
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from fricid.identify.dynamic.trajectory import fit_trajectory
from fricid.io import read_rawlog, write_rawlog
from fricid.io.urdf import STANDARD_GRAVITY, GravityLoad, Robot, gravity_coefficients, read_urdf
from fuzzing import RngChooser, WrongAnswer, classify

# --------------------------------------------------------------------------- URDF

#: Refused in every numeric attribute that is read.
BAD_NUMBERS = [
    "1e308",
    "-1e308",
    "1e300",
    "0_1",
    "1_000",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e999",
    "0x10",
    "\u0661",
    "",
    "1,5",
    "1e",
    "--1",
    "9" * 400,
    "+-1",
]
#: Per kind of attribute: more refused values, and odd values that are read as numbers.
BAD_BY_KIND = {
    "mass": ["1e-320", "-1", "1e7", "5e-10"],
    "length": ["1001", "-1e4"],
    "angle": ["1001", "1e300"],
}
ODD_BY_KIND = {
    "mass": ["0", "-0", "1e-9", "1e6", "+.5", "5."],
    "length": ["1e-320", "-0", "999.5", "+.5", "5.", "1E-3"],
    "angle": ["1e-320", "-1000", "3.14159", "+.5"],
}
AXES_OK = ["0 1 0", "1 0 0", "0.6 0.8 0", "0 -5 0", "3 0 4", "0 0 1"]
AXES_BAD = ["0 0 0", "0 1e-9 0", "0 1e308 1e308", "nan 0 1", "0 1", "0 1 0 0", "0 0_1 0"]
GRAPH_DEFECTS = [
    "cycle",
    "self_loop",
    "second_parent",
    "missing_link",
    "second_root",
    "duplicate_link",
    "duplicate_joint",
    "joint_into_root",
]
FILE_DEFECTS = ["doctype", "declared_utf7", "declared_utf16_in_utf8"]
#: Encodings that keep the document: (codec, declared name, a BOM is written by the codec).
ENCODINGS = {
    "utf-8": "UTF-8",
    "utf-8-sig": "UTF-8",
    "utf-16": "UTF-16",
    "utf-16-le": "UTF-16",
    "utf-16-be": "UTF-16",
    "utf-32": "UTF-32",
    "latin-1": "ISO-8859-1",
}
ROTATING = ("revolute", "continuous")


@dataclass
class UrdfCase:
    """A generated URDF: its elements, what is wrong with it, and what it should read as."""

    links: list[str] = field(default_factory=list)
    joints: list[str] = field(default_factory=list)
    masses: dict[str, float] = field(default_factory=dict)
    parent: dict[str, str] = field(default_factory=dict)  # child link -> parent link
    child: dict[str, str] = field(default_factory=dict)  # joint -> child link
    kinds: dict[str, str] = field(default_factory=dict)  # joint -> type
    extent: float = 1.0  # sum of |coordinates| written: a bound on any lever arm [m]
    defects: list[str] = field(default_factory=list)
    changes: list[str] = field(default_factory=list)
    encoding: str = "utf-8"
    doctype: bool = False
    declared: str | None = None  # the declaration's encoding, when it differs from the codec
    pick: int = 0  # which rotating joint eq. 7 is asked for

    def text(self) -> str:
        name = "bräu" if self.encoding == "latin-1" else "arm"
        head = f'<?xml version="1.0" encoding="{self.declared or ENCODINGS[self.encoding]}"?>'
        dtd = '<!DOCTYPE robot [<!ENTITY m "1">]>' if self.doctype else ""
        body = "\n".join([*self.links, *self.joints])
        return f'{head}\n{dtd}<robot name="{name}">\n{body}\n</robot>\n'

    def data(self) -> bytes:
        return self.text().encode(self.encoding, "xmlcharrefreplace")

    def downstream(self, joint: str) -> list[str]:
        out, todo = [], [self.child[joint]]
        while todo:
            link = todo.pop()
            out.append(link)
            todo.extend(c for c, p in self.parent.items() if p == link)
        return out


def _number(case: UrdfCase, ch: RngChooser, kind: str, value: float) -> tuple[str, float]:
    """``value`` as text, or (rarely) an odd token read as a number, or a refused one (a
    defect); the text and the number it is read as."""
    roll = ch.integer(0, 299)
    if roll == 0:
        token = ch.choice([*BAD_NUMBERS, *BAD_BY_KIND[kind]])
        case.defects.append(f"{kind} {token[:12]!r}")
        return token, math.nan
    if roll < 6:
        token = ch.choice(ODD_BY_KIND[kind])
        case.changes.append(f"{kind} {token}")
        value = abs(float(token)) if kind == "mass" else float(token)
        text = token
    else:
        text = repr(value)
    if kind == "length":
        case.extent += abs(value)
    return text, value


def _vector(case: UrdfCase, ch: RngChooser, kind: str) -> str:
    return " ".join(_number(case, ch, kind, ch.integer(-1000, 1000) / 1000)[0] for _ in range(3))


def _link(case: UrdfCase, ch: RngChooser, name: str) -> str:
    if ch.integer(0, 4) == 0:
        case.masses[name] = 0.0
        return f'<link name="{name}"/>'
    text, case.masses[name] = _number(case, ch, "mass", ch.integer(1, 5000) / 1000)
    com = _vector(case, ch, "length")
    rpy = " ".join(repr(ch.integer(-3000, 3000) / 1000) for _ in range(3))
    return (
        f'<link name="{name}"><inertial><origin xyz="{com}" rpy="{rpy}"/>'
        f'<mass value="{text}"/></inertial></link>'
    )


def _joint(case: UrdfCase, ch: RngChooser, name: str, parent: str, child: str) -> str:
    kind = ch.choice(["revolute", "revolute", "continuous", "prismatic", "fixed"])
    case.kinds[name] = kind
    case.child[name] = child
    axis = ch.choice(AXES_OK)
    if kind != "fixed" and ch.integer(0, 29) == 0:
        axis = ch.choice(AXES_BAD)
        case.defects.append(f"axis {axis!r}")
    xyz = _vector(case, ch, "length")
    rpy = _vector(case, ch, "angle")
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/></joint>'
    )


def _graph_defect(case: UrdfCase, ch: RngChooser, kind: str) -> None:
    links = list(case.masses)
    case.defects.append(kind)
    fixed = '<joint name="{}" type="fixed"><parent link="{}"/><child link="{}"/></joint>'
    if kind == "cycle":
        case.links += ['<link name="ca"/>', '<link name="cb"/>']
        case.joints += [_joint(case, ch, "jca", "ca", "cb"), _joint(case, ch, "jcb", "cb", "ca")]
    elif kind == "self_loop":
        case.links.append('<link name="sl"/>')
        case.joints.append(_joint(case, ch, "jsl", "sl", "sl"))
    elif kind == "second_parent" and len(links) > 1:
        c = ch.choice(links[1:])
        case.joints.append(fixed.format("jdup", ch.choice([n for n in links if n != c]), c))
    elif kind == "missing_link":
        case.joints.append(fixed.format("jghost", ch.choice(links), "ghost"))
    elif kind == "second_root":
        case.links.append('<link name="island"/>')
    elif kind == "duplicate_link":
        case.links.append(ch.choice(case.links))
    elif kind == "duplicate_joint" and case.joints:
        case.joints.append(ch.choice(case.joints))
    else:  # joint_into_root, or the kinds above on a robot too small for them
        case.defects[-1] = "joint_into_root"
        case.joints.append(fixed.format("jroot", ch.choice(links), links[0]))


def urdf_case(ch: RngChooser) -> UrdfCase:
    """A random URDF case (module notes)."""
    case = UrdfCase()
    n = ch.integer(1, 7)
    names = [f"l{i}" for i in range(n)]
    for name in names:
        case.links.append(_link(case, ch, name))
    for i in range(1, n):
        parent = names[ch.integer(0, i - 1)]
        case.parent[names[i]] = parent
        case.joints.append(_joint(case, ch, f"j{i}", parent, names[i]))
    for _ in range(ch.integer(0, 2) // 2 * ch.integer(1, 2)):
        _graph_defect(case, ch, ch.choice(GRAPH_DEFECTS))
    case.encoding = ch.choice([*ENCODINGS, "utf-8", "utf-8"])
    if case.encoding != "utf-8":
        case.changes.append(case.encoding)
    if ch.integer(0, 9) == 0:
        defect = ch.choice(FILE_DEFECTS)
        case.defects.append(defect)
        if defect == "doctype":
            case.doctype = True
        elif defect == "declared_utf7":
            case.declared = "UTF-7"
        elif ENCODINGS[case.encoding] == "UTF-16":
            case.declared = "UTF-8"
        else:
            case.declared = "UTF-16"
    case.pick = ch.integer(0, 6)
    return case


def read_case(path: Path, pick: int) -> Robot | GravityLoad:
    """The URDF read, then eq. 7 of its rotating joint number ``pick`` (modulo their count);
    the robot itself when it has none."""
    robot = read_urdf(path)
    rotating = [n for n, j in robot.joints.items() if j.kind in ROTATING]
    if not rotating:
        return robot
    return gravity_coefficients(robot, rotating[pick % len(rotating)])


def check_urdf(case: UrdfCase, result: Any) -> None:
    """Raise :class:`WrongAnswer` unless ``result`` is what ``case`` describes."""
    if case.defects:
        raise WrongAnswer(f"a URDF with {case.defects} was read")
    if isinstance(result, Robot):
        if result.root != "l0" or set(result.links) != set(case.masses):
            raise WrongAnswer(f"root {result.root!r}, links {sorted(result.links)}")
        return
    if not isinstance(result, GravityLoad):
        raise WrongAnswer(f"unexpected result {type(result).__name__}")
    p = np.array([result.p_x, result.p_y])
    mass = sum(case.masses[name] for name in case.downstream(result.joint))
    if not np.isfinite(p).all() or not math.isclose(result.mass, mass, rel_tol=1e-12):
        raise WrongAnswer(f"p = {p}, mass {result.mass} (the structure holds {mass})")
    bound = STANDARD_GRAVITY * mass * case.extent * (1 + 1e-9)
    if (np.abs(p) > bound).any():
        raise WrongAnswer(f"p = {p} over g m times the extent ({bound:.6g} N m)")


def run_urdf(folder: Path, ch: RngChooser, n: int) -> tuple[str, list[str]]:
    """One generated URDF: its outcome ("error" or "valid") and its defects and changes."""
    case = urdf_case(ch)
    path = folder / f"case{n}.urdf"
    path.write_bytes(case.data())
    try:
        outcome, result = classify(lambda: read_case(path, case.pick), path, lambda _r: None)
        if outcome == "valid":
            try:
                check_urdf(case, result)
            except WrongAnswer as exc:
                raise WrongAnswer(f"{case.defects or case.changes}: {exc}") from None
            if case.changes:  # the same document in UTF-8, with no odd token changed
                plain = UrdfCase(**{**case.__dict__, "encoding": "utf-8", "declared": None})
                path.write_bytes(plain.data())
                again = read_case(path, case.pick)
                if _values(again) != _values(result):
                    raise WrongAnswer(f"{case.changes}: {_values(result)} != {_values(again)}")
    finally:
        path.unlink(missing_ok=True)
    return outcome, case.defects or case.changes


def _values(result: Any) -> tuple:
    if isinstance(result, GravityLoad):
        return (result.p_x, result.p_y, result.mass, result.links)
    return (result.root, tuple(sorted(result.links)))


# --------------------------------------------------------------------------- trajectory

#: The virtual joint's truth (``fricid simulate --trajectory``): inertia and the static part.
TRUTH = {"inertia": 0.01, "tau_c": 0.5, "tau_v": 0.2}

#: A valid result further than this factor from the truth is a wrong answer.
ABSURD = 1.5

#: The damages, in the order they are applied (rows removed first, then the stamps changed:
#: a later damage never undoes an earlier one's defect).
TRAJECTORY_KINDS = [
    "jitter",
    "drop",
    "slow_stretch",
    "hole",
    "moved_stamp",
    "repeated_stamp",
    "stuck_all",
    "stuck_run",
]

COLUMNS = ("time", "position", "velocity", "current", "temperature")


@cache
def trajectory_base(folder: str) -> tuple[str, dict[str, np.ndarray]]:
    """The undamaged log: its CSV header lines and columns (simulated once per folder)."""
    from fricid.sim import Joint
    from fricid.sim import trajectory as tr

    joint = Joint(law=lambda v, load, temp: np.zeros_like(v), p_x=0.3, p_y=0.1, inertia=0.01)
    log = tr.simulate_trajectory(tr.multisine(duration=2.0, seed=0), tr.LuGreTruth(), joint)
    path = Path(folder) / "base_trajectory.csv"
    write_rawlog(log, path)
    lines = path.read_text().splitlines()
    head = "\n".join(line for line in lines if line.startswith("#") or line.startswith("time"))
    return head, {name: np.asarray(getattr(log, name), dtype=float) for name in COLUMNS}


def damage(cols: dict[str, np.ndarray], kind: str, ch: RngChooser) -> str | None:
    """Damage ``cols`` in place (or replace them); the defect that must be refused, if any."""
    t, n = cols["time"], len(cols["time"])
    k = ch.integer(1, n - 2)
    if kind == "hole":  # the clock jumps: every later stamp is late (the 10 s)
        gap = ch.choice([0.0045, 0.006, 0.02, 0.05, 0.5, 10.0, 1e6])
        t[k:] += gap
        return f"hole {gap} s"
    if kind == "moved_stamp":
        k = ch.choice([0, k, n - 1])
        delta = ch.choice([1e6, -1e6, 0.5, -0.5, 2e-4, -2e-4])
        t[k] += delta
        return f"stamp {k} moved by {delta} s" if abs(delta) >= 0.5 else None
    if kind == "repeated_stamp":
        t[k + 1] = t[k]
        return f"stamp {k + 1} repeated"
    if kind == "drop":  # rows lost: the stamps stay true
        m = ch.choice([1, 2, 3, 4, 10, 100])
        keep = np.r_[0:k, min(k + m, n - 1) : n]
        for name in COLUMNS:
            cols[name] = cols[name][keep]
        return f"{m} rows dropped" if m >= 5 and k + m < n - 1 else None
    if kind == "jitter":
        t += np.array([ch.integer(-20, 20) for _ in range(n)]) * 1e-6
        return None
    if kind == "slow_stretch":
        keep = np.ones(n, bool)
        keep[k : k + 300] = np.arange(len(keep[k : k + 300])) % 3 == 0
        for name in COLUMNS:
            cols[name] = cols[name][keep]
        return None
    if kind == "stuck_all":
        cols["current"][:] = ch.choice([10.0, 0.0, float(cols["current"][0])])
        return "current stuck in every row"
    if kind == "stuck_run":
        length = ch.choice([5, 20, 40, 60, 100, 400])
        cols["current"][k : k + length] = cols["current"][k]
        return None
    raise AssertionError(kind)


def trajectory_value(result: Any, name: str) -> float:
    if name == "inertia":
        return float(result.provenance["trajectory"]["joint"]["inertia"]["value"])
    return float(result.params[name])


def check_trajectory(defects: list[str], result: Any) -> None:
    """Raise :class:`WrongAnswer` unless ``result`` is a fit near the truth of a log without
    a defect that must be refused."""
    if defects:
        raise WrongAnswer(f"a log with {defects} was fitted")
    if not isinstance(getattr(result, "parameters", None), dict):
        raise WrongAnswer(f"unexpected result {type(result).__name__}")
    for name, truth in TRUTH.items():
        value = trajectory_value(result, name)
        if not (math.isfinite(value) and truth / ABSURD <= value <= truth * ABSURD):
            raise WrongAnswer(f"{name} = {value!r} (truth {truth})")


def run_trajectory(folder: Path, ch: RngChooser, n: int) -> tuple[str, list[str]]:
    """One damaged trajectory log: its outcome and the damage done."""
    head, base = trajectory_base(str(folder))
    cols = {name: values.copy() for name, values in base.items()}
    drawn = {ch.choice(TRAJECTORY_KINDS) for _ in range(ch.integer(1, 2))}
    kinds = [kind for kind in TRAJECTORY_KINDS if kind in drawn]
    done = [(kind, damage(cols, kind, ch)) for kind in kinds]
    defects = [d for _, d in done if d]
    rows = np.column_stack([cols[name] for name in COLUMNS])
    path = folder / f"traj{n}.csv"
    path.write_text(head + "\n" + "\n".join(",".join(map(repr, r.tolist())) for r in rows))
    try:
        outcome, result = classify(
            lambda: fit_trajectory(read_rawlog(path), "stribeck"), path, lambda _r: None
        )
        if outcome == "valid":
            try:
                check_trajectory(defects, result)
            except WrongAnswer as exc:
                raise WrongAnswer(f"{done}: {exc}") from None
    finally:
        path.unlink(missing_ok=True)
    return outcome, defects or kinds


# --------------------------------------------------------------------------- resources


def measured(call: Callable[[], Any]) -> tuple[Any, float, float]:
    """``call()``, its duration [s] and its peak of traced memory [bytes]."""
    tracemalloc.start()
    start = time.perf_counter()
    try:
        out = call()
        return out, time.perf_counter() - start, float(tracemalloc.get_traced_memory()[1])
    finally:
        tracemalloc.stop()
