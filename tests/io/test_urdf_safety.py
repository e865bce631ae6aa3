"""Hostile URDFs (issue 25): graphs that are not trees, encodings that hide a DOCTYPE, files
that are not regular files, and numbers outside physical ranges. Each is refused by
:func:`fricid.io.urdf.read_urdf` in one line naming the file and the joint, link, element or
attribute; the files that are trees of plausible numbers still load."""

from __future__ import annotations

import os
import threading

import pytest

from fricid.errors import DataError
from fricid.io.urdf import STANDARD_GRAVITY, read_urdf, urdf_gravity

G = STANDARD_GRAVITY

#: One arm (base -> upper by 'shoulder') and whatever ``{extra}`` adds beside it.
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="{com}" rpy="0 0 0"/><mass value="{mass}"/>
  </inertial></link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.5" rpy="{rpy}"/><axis xyz="{axis}"/>
  </joint>
{extra}
</robot>
"""
DEFAULTS = {"com": "0.2 0 0", "mass": "2", "rpy": "0 0 0", "axis": "0 1 0", "extra": ""}

#: Two links that hang on each other beside the tree: base stays the only root.
CYCLE = """  <link name="a"/><link name="b"/>
  <joint name="ab" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/></joint>
  <joint name="ba" type="revolute"><parent link="b"/><child link="a"/><axis xyz="0 1 0"/></joint>
"""
SELF_LOOP = """  <link name="c"/>
  <joint name="cc" type="revolute"><parent link="c"/><child link="c"/><axis xyz="0 1 0"/></joint>
"""


def arm(tmp_path, name="robot.urdf", encoding="utf-8", **fields):
    path = tmp_path / name
    path.write_bytes(ARM.format(**{**DEFAULTS, **fields}).encode(encoding))
    return path


def refused(path, *words):
    """read_urdf's one-line DataError naming the file and every word."""
    with pytest.raises(DataError) as info:
        read_urdf(path)
    message = str(info.value)
    assert message.startswith(str(path)) and "\n" not in message, message
    for word in words:
        assert word in message, message
    return message


def test_the_plain_arm_loads(tmp_path):
    got = urdf_gravity(arm(tmp_path), "shoulder")
    assert got.p_x == pytest.approx(2 * G * 0.2, rel=1e-12) and got.mass == 2


# --------------------------------------------------------------------------- graphs


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (CYCLE, ("form a cycle", "'ab'", "'ba'")),
        (SELF_LOOP, ("<joint name='cc'>", "parent and child are the same link 'c'")),
        (
            "<link name='d'/><joint name='d1' type='fixed'><parent link='base'/>"
            "<child link='d'/></joint><joint name='d2' type='fixed'><parent link='upper'/>"
            "<child link='d'/></joint>",
            ("<joint name='d2'>", "already has parent joint 'd1'"),
        ),
        (
            "<joint name='e' type='fixed'><parent link='upper'/><child link='ghost'/></joint>",
            ("<joint name='e'>", "names link 'ghost', which is not defined"),
        ),
        ("<link name='island'/>", ("one tree", "island")),
    ],
)
def test_graphs_that_are_not_one_tree(tmp_path, extra, words):
    """A cycle beside the tree is refused even when the joint asked for is a normal one (it
    was accepted, and a joint of the cycle grew memory without end)."""
    refused(arm(tmp_path, extra=extra), *words)


def test_a_cycle_without_a_root(tmp_path):
    text = (
        "<robot><link name='a'/><link name='b'/>"
        "<joint name='ab' type='fixed'><parent link='a'/><child link='b'/></joint>"
        "<joint name='ba' type='fixed'><parent link='b'/><child link='a'/></joint></robot>"
    )
    path = tmp_path / "ring.urdf"
    path.write_text(text)
    refused(path, "form a cycle")


def test_a_long_chain_is_a_tree(tmp_path):
    """The graph check walks each link once: 3000 links in a chain load at once."""
    n = 3000
    links = "".join(
        f"<link name='l{i}'><inertial><mass value='0.1'/></inertial></link>" for i in range(n)
    )
    joints = "".join(
        f"<joint name='j{i}' type='revolute'><parent link='l{i}'/><child link='l{i + 1}'/>"
        f"<origin xyz='0.001 0 0'/><axis xyz='0 1 0'/></joint>"
        for i in range(n - 1)
    )
    path = tmp_path / "chain.urdf"
    path.write_text(f"<robot>{links}{joints}</robot>")
    robot = read_urdf(path)
    assert robot.root == "l0" and len(robot.downstream("j0")) == n - 1


# --------------------------------------------------------------------------- the file


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be", "utf-32"])
def test_a_doctype_in_utf16_is_refused(tmp_path, encoding):
    """Saved as UTF-16 the DOCTYPE's bytes do not read '<!DOCTYPE', and expat expanded the
    entity: the check now runs on the decoded text."""
    text = (
        '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY m "2">]><robot name="x">'
        "<link name='a'><inertial><mass value='&m;'/></inertial></link></robot>"
    )
    path = tmp_path / "wide.urdf"
    path.write_bytes(text.encode(encoding))
    refused(path, "DOCTYPE")


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16", "utf-16-le", "utf-32"])
def test_other_unicode_encodings_read_the_same(tmp_path, encoding):
    plain = urdf_gravity(arm(tmp_path), "shoulder")
    wide = urdf_gravity(arm(tmp_path, "wide.urdf", encoding), "shoulder")
    assert (wide.p_x, wide.p_y, wide.mass) == (plain.p_x, plain.p_y, plain.mass)


def test_latin1_declared_reads(tmp_path):
    text = ARM.format(**DEFAULTS).replace('<?xml version="1.0"?>', "")
    text = '<?xml version="1.0" encoding="ISO-8859-1"?>' + text.replace('name="arm"', 'name="bräu"')
    path = tmp_path / "latin.urdf"
    path.write_bytes(text.encode("latin-1"))
    assert read_urdf(path).name == "bräu"


@pytest.mark.parametrize(
    ("head", "encoding", "words"),
    [
        ('<?xml version="1.0" encoding="UTF-7"?>', "utf-8", ("encoding 'UTF-7'", "UTF-8")),
        ('<?xml version="1.0" encoding="UTF-16"?>', "utf-8", ("UTF-16",)),
        ('<?xml version="1.0" encoding="UTF-8"?>', "utf-16", ("UTF-8", "UTF-16")),
    ],
)
def test_declarations_that_do_not_match(tmp_path, head, encoding, words):
    text = ARM.format(**DEFAULTS).replace('<?xml version="1.0"?>', head)
    path = tmp_path / "declared.urdf"
    path.write_bytes(text.encode(encoding))
    refused(path, *words)


def test_not_utf8(tmp_path):
    path = arm(tmp_path)
    path.write_bytes(path.read_bytes().replace(b'name="arm"', b'name="\xe9"'))
    refused(path, "not valid UTF-8")


def test_a_device_is_refused(tmp_path):
    """/dev/zero's size reads 0, so the size check passed and the read never ended."""
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero")
    refused("/dev/zero", "not a regular file")


def test_a_fifo_is_refused_without_waiting(tmp_path):
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs here")
    fifo = tmp_path / "pipe.urdf"
    os.mkfifo(fifo)
    outcome: list[BaseException | None] = []

    def read() -> None:
        try:
            read_urdf(fifo)
            outcome.append(None)
        except BaseException as exc:  # handed to the test thread
            outcome.append(exc)

    thread = threading.Thread(target=read, daemon=True)
    thread.start()
    thread.join(5.0)
    if thread.is_alive():  # unblock the reader so the thread ends
        with open(fifo, "wb"):
            pass
        thread.join(5.0)
        pytest.fail("reading a FIFO waited for a writer")
    assert isinstance(outcome[0], DataError) and "not a regular file" in str(outcome[0])


def test_a_folder_is_refused(tmp_path):
    refused(tmp_path, "URDF")


# --------------------------------------------------------------------------- values


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("axis", "0 1e308 1e308", ("<joint name='shoulder'> <axis>", "xyz='0 1e308 1e308'")),
        ("axis", "0 1e-9 0", ("<joint name='shoulder'> <axis>", "norm")),
        ("com", "1e308 0 0", ("<link name='upper'> <inertial><origin>", "xyz='1e308 0 0'")),
        ("com", "1001 0 0", ("<inertial><origin>", "over 1000")),
        ("mass", "1e-320", ("<link name='upper'> <inertial><mass>", "value=1e-320")),
        ("mass", "1e7", ("<inertial><mass>", "value=10000000.0")),
        ("mass", "-1", ("<inertial><mass>", "value=-1.0")),
        ("mass", "0_1", ("<inertial><mass>", "value='0_1'", "plain decimal")),
        ("mass", "1e999", ("<inertial><mass>", "value='1e999'")),
        ("mass", "nan", ("<inertial><mass>", "value='nan'")),
        ("mass", "inf", ("<inertial><mass>", "value='inf'")),
        ("mass", "0x10", ("<inertial><mass>", "value='0x10'")),
        ("mass", "\u0661", ("<inertial><mass>", "plain decimal")),
        ("mass", "1 2", ("<inertial><mass>", "is not 1 plain decimal")),
        ("rpy", "1e300 0 0", ("<joint name='shoulder'> <origin>", "rpy='1e300 0 0'")),
        ("rpy", "0 0 1_0", ("<joint name='shoulder'> <origin>", "rpy='0 0 1_0'")),
    ],
)
def test_values_outside_their_range(tmp_path, field, value, words):
    """Each gave a wrong answer before: K = 0 +- 0 (the axis), 1.6e308 +- inf (the centre of
    mass), a mass of 1e-320 kg accepted, a negative K (the angle), 0_1 read as 1 kg."""
    refused(arm(tmp_path, **{field: value}), *words)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("mass", "0"),
        ("mass", "1e-9"),
        ("mass", "+2.5E+1"),
        ("mass", ".5"),
        ("com", "999.5 -1e-300 0"),
        ("rpy", "-1000 3.14159 1e2"),
        ("axis", "0 -5 0"),
    ],
)
def test_values_inside_their_range_load(tmp_path, field, value):
    robot = read_urdf(arm(tmp_path, **{field: value}))
    assert robot.joints["shoulder"].axis @ robot.joints["shoulder"].axis == pytest.approx(1.0)


def test_a_massless_link_is_massless(tmp_path):
    """``<mass value="0"/>`` is a link without mass, as a link without ``<inertial>`` is."""
    extra = (
        "<link name='tool'><inertial><mass value='0'/></inertial></link>"
        "<joint name='flange' type='fixed'><parent link='upper'/><child link='tool'/></joint>"
    )
    got = urdf_gravity(arm(tmp_path, extra=extra), "shoulder")
    assert got.mass == 2 and got.p_x == pytest.approx(2 * G * 0.2, rel=1e-12)


@pytest.mark.parametrize("joint", ["ab", "cc", "shoulder"])
def test_cli_refuses_a_cyclic_urdf_in_one_line(tmp_path, joint):
    """``extract --urdf-joint`` on a joint of the cycle, on a self-loop, or on the normal
    joint: exit 2, one line naming the file, no samples file (memory grew without end, or the
    file was accepted)."""
    from typer.testing import CliRunner

    from fricid.cli import app
    from fricid.io import write_rawlog
    from fricid.sim import preset, simulate_log

    log = write_rawlog(simulate_log(preset("paper1", "quick"), seed=1), tmp_path / "log.parquet")
    urdf = arm(tmp_path, extra=CYCLE + SELF_LOOP)
    out = tmp_path / "s.csv"
    args = ["extract", str(log), "-o", str(out), "--urdf", str(urdf), "--urdf-joint", joint]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 2, res.output
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert len(lines) == 1 and str(urdf.name) in lines[0], res.output
    assert not out.exists()
