"""No traceback from any file or command line we are handed: generated project files, model files, bags, arguments.

Each property feeds generated input to the real entry point and accepts
exactly two outcomes: it works, or it fails with the one error the
program reports as a single line (``ProjectError``, ``ModelError``,
``BagError``; an exit status of 2).  Anything else (an exception of
another type, a message of two lines) is a bug.  ``make test`` runs a
fixed set of examples; ``make fuzz`` many more (``tests/fuzzing.py``).
"""

from __future__ import annotations

import contextlib
import io
import shutil

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from tutorial.core.project import ProjectError, load_project
from tutorial.core.world import ModelEntry, ModelError, build_world
from tutorial.tools import rtt_bag as bag_cli
from tutorial.tools.bag.info import bag_info
from tutorial.tools.bag.reader import BagError, iter_raw, read_messages
from tutorial.tools.bag.recover import recover
from tutorial.tools.bag.series import joint_series

from conftest import MODEL, PROJECT
from fuzzing import examples

pytestmark = pytest.mark.unit

TEXT = st.text(st.characters(blacklist_categories=("Cs",)), max_size=40)  # what a YAML file can hold
SCALARS = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(10**400), max_value=10**400)
    | st.floats(allow_nan=True, allow_infinity=True)
    | TEXT
)
YAML_VALUES = st.recursive(
    SCALARS, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(TEXT, inner, max_size=4), max_leaves=12
)


def one_line(text: str) -> bool:
    return len(str(text).splitlines()) == 1


# ------------------------------------------------------------ project files
def good_project_tree() -> dict:
    return yaml.safe_load((PROJECT / "step2.yaml").read_text())


CLASS_PATHS = st.sampled_from(
    [
        "tutorial.controllers.joint_state_publisher:RttJointStatePublisher",
        "tutorial.controllers.joint_state_publisher:Nope",
        "tutorial.controllers:RttJointStatePublisher",
        "rtt_fuzz_no_such_module:X",
        ":",
        "..:x",
        "tutorial..x:Y",
    ]
) | TEXT.map(lambda t: f"rtt_fuzz_no_such_module.{t}:X")  # never a real module: importing runs its code


@st.composite
def mutated_projects(draw) -> object:
    """``project/step2.yaml`` with one to three of its values (or keys) replaced by generated ones."""
    doc = good_project_tree()
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(list(_paths(doc))))
        target = draw(st.sampled_from(["value", "value", "class", "key"]))
        if not path:  # the whole document
            doc = draw(YAML_VALUES)
            continue
        parent, key = _walk(doc, path[:-1]), path[-1]
        if target == "class":
            value = draw(CLASS_PATHS)
        elif target == "key" and isinstance(parent, dict):
            parent[draw(TEXT)] = parent.pop(key)
            continue
        else:
            value = draw(YAML_VALUES)
        parent[key] = value
    return doc


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, (*prefix, i))


def _walk(node, path):
    for key in path:
        node = node[key]
    return node


def load_or_project_error(path) -> None:
    """The property: ``load_project`` works, or raises one ProjectError line that names the file."""
    try:
        load_project(path)
    except ProjectError as exc:
        assert one_line(exc), repr(str(exc))
        assert str(exc).startswith(str(path)), str(exc)


@examples(60)
@given(doc=mutated_projects())
def test_a_mutated_project_file_loads_or_gives_one_line(tmp_path_factory, doc):
    path = tmp_path_factory.mktemp("project") / "p.yaml"
    # The models' files stay where step2.yaml names them (relative to project/).
    text = yaml.safe_dump(doc, allow_unicode=True).replace("../model/", f"{MODEL}/")
    path.write_text(text, encoding="utf-8")
    load_or_project_error(path)


@examples(40)
@given(data=st.binary(max_size=400) | TEXT.map(str.encode) | YAML_VALUES.map(lambda v: yaml.safe_dump(v).encode()))
def test_any_bytes_as_a_project_file_give_one_line(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("project") / "junk.yaml"
    path.write_bytes(data)
    load_or_project_error(path)


def test_deep_nesting_and_a_device_as_project_files_give_one_line(tmp_path):
    (tmp_path / "deep.yaml").write_text("[" * 5_000)
    for path in (tmp_path / "deep.yaml", "/dev/zero", tmp_path, tmp_path / "missing.yaml"):
        with pytest.raises(ProjectError) as info:
            load_project(path)
        assert one_line(info.value), str(info.value)


# ------------------------------------------------------------ model files (MJCF) a project names
GOOD_MODELS = [MODEL / "tank.xml", MODEL / "crane.xml", MODEL / "room.xml"]


@st.composite
def mutated_models(draw) -> bytes:
    """A shipped MJCF file with a span deleted, replaced by generated text, or the file cut short."""
    text = draw(st.sampled_from(GOOD_MODELS)).read_bytes()
    for _ in range(draw(st.integers(1, 3))):
        start = draw(st.integers(0, len(text)))
        end = draw(st.integers(start, min(len(text), start + 80)))
        kind = draw(st.sampled_from(["delete", "replace", "cut", "insert"]))
        if kind == "cut":
            text = text[:start]
        elif kind == "delete":
            text = text[:start] + text[end:]
        else:
            junk = draw(st.sampled_from([b"<", b">", b'"', b"=", b"/>", b"<body>", b"nan", b"-1e400", b"\x00"]))
            junk = junk if draw(st.booleans()) else draw(st.binary(max_size=12))
            text = text[:start] + junk + text[end if kind == "replace" else start :]
    return text


def build_or_model_error(path) -> None:
    """The property: the world builds (and a body of it can be made), or one ModelError line names the file."""
    import mujoco

    from tutorial.core.body import Body

    try:
        model = build_world([ModelEntry("M", path)])
    except ModelError as exc:
        assert one_line(exc), repr(str(exc))
        assert str(exc).startswith(str(path)) or str(exc).startswith("the models"), str(exc)
        return
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    Body(model, data, "M")  # what App.open does next: it must not fail on a model that built


@examples(40)
@given(text=mutated_models())
def test_a_mutated_model_file_builds_or_gives_one_line(tmp_path_factory, text):
    folder = tmp_path_factory.mktemp("model")
    for mesh_folder in ("meshes", "assets"):  # what the shipped models load beside them, if anything
        if (MODEL / mesh_folder).is_dir():
            shutil.copytree(MODEL / mesh_folder, folder / mesh_folder)
    path = folder / "m.xml"
    path.write_bytes(text)
    build_or_model_error(path)


@examples(20)
@given(data=st.binary(max_size=300))
def test_any_bytes_as_a_model_file_give_one_line(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("model") / "junk.xml"
    path.write_bytes(data)
    build_or_model_error(path)


# ------------------------------------------------------------ bags (MCAP)
@pytest.fixture(scope="module")
def bag_bytes(tmp_path_factory) -> bytes:
    from test_bag import good_bag

    return good_bag(tmp_path_factory.mktemp("bag") / "good.mcap", n=1100).read_bytes()  # 3 chunks


@st.composite
def damaged_bags(draw, data: bytes) -> bytes:
    """A good bag cut short, with bytes flipped, overwritten or inserted, in one to three places."""
    out = bytearray(data)
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["cut", "flip", "overwrite", "insert", "zero"]))
        at = draw(st.integers(0, max(0, len(out) - 1)))
        if kind == "cut":
            del out[at:]
        elif kind == "flip" and out:
            out[at] ^= 1 << draw(st.integers(0, 7))
        elif kind == "overwrite":
            junk = draw(st.binary(min_size=1, max_size=16))
            out[at : at + len(junk)] = junk
        elif kind == "zero":
            out[at : at + draw(st.integers(1, 64))] = bytes(64)[: len(out[at : at + 64])]
        else:
            out[at:at] = draw(st.binary(min_size=1, max_size=16))
    return bytes(out)


def read_or_bag_error(path, out) -> None:
    """The property: every reader works or raises one BagError line; recover works or says why, one line."""
    for read in (bag_info, lambda p: list(iter_raw(p)), lambda p: list(read_messages(p)), joint_series):
        try:
            read(path)
        except BagError as exc:
            assert one_line(exc), repr(str(exc))
    try:
        recover(path, out, overwrite=True)
    except BagError as exc:
        assert one_line(exc), repr(str(exc))
        return
    bag_info(out)  # the copy is whole, and our reader reads it ...
    from mcap.reader import make_reader

    with open(out, "rb") as f:  # ... and so does the stock reader, every message
        reader = make_reader(f, validate_crcs=True)
        assert reader.get_summary().statistics.message_count == sum(1 for _ in reader.iter_messages())


def test_damaged_bags_are_read_or_refused_in_one_line(bag_bytes, tmp_path_factory):
    @examples(40)
    @given(data=damaged_bags(bag_bytes))
    def property_(data):
        folder = tmp_path_factory.mktemp("bag")
        (folder / "d.mcap").write_bytes(data)
        read_or_bag_error(folder / "d.mcap", folder / "out.mcap")

    property_()


@examples(20)
@given(data=st.binary(max_size=200).map(lambda b: b"\x89MCAP0\r\n" + b))
def test_junk_after_the_magic_is_read_or_refused_in_one_line(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("bag")
    (folder / "j.mcap").write_bytes(data)
    read_or_bag_error(folder / "j.mcap", folder / "out.mcap")


# ------------------------------------------------------------ command lines
ARG_TOKENS = (
    st.sampled_from(
        [
            "--ros-args",
            "-r",
            "-p",
            "__node:=x",
            "a:=b",
            "--params-file",
            "--",
            "-h",
            "--json",
            "--headless",
            "--duration",
            "nan",
            "inf",
            "-1",
            "0",
            "1e309",
            "--fast",
            "--rate",
            "--start-offset",
            "--delay",
            "--topics",
            "--loop",
            "-o",
            "--overwrite",
            "--compression",
            "zstd",
            "--tf",
            "--tf-frame-prefix",
            "{body}/",
            "{body.x}",
            "/",
            "missing.mcap",
            "missing.yaml",
            "/dev/zero",
            ".",
            "",
        ]
    )
    | TEXT
)


def exit_status(main, argv) -> int:
    """``main(argv)``'s exit status, an argparse exit included; stderr and stdout swallowed."""
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        try:
            return main(argv)
        except SystemExit as exc:
            return exc.code if isinstance(exc.code, int) else 2


@examples(40)
@given(command=st.sampled_from(["info", "play", "recover"]), args=st.lists(ARG_TOKENS, max_size=6))
def test_rtt_bag_command_lines_end_in_a_status(tmp_path_factory, monkeypatch, command, args):
    """``info``, ``play`` and ``recover`` with generated arguments, in an empty folder: no file to read, so
    nothing is published (``record`` would start recording: its arguments are only parsed, below)."""
    monkeypatch.chdir(tmp_path_factory.mktemp("cwd"))
    assert exit_status(bag_cli.main, ["rtt-bag", command, *args]) in (0, 2)


@examples(30)
@given(args=st.lists(ARG_TOKENS, max_size=6))
def test_rtt_bag_record_arguments_parse_or_exit_2(args):
    from tutorial.ros.program import parse_command_line

    def parse(argv):
        parse_command_line(bag_cli.build_parser(), argv)
        return 0

    assert exit_status(parse, ["rtt-bag", "record", *args]) in (0, 2)


@examples(40)
@given(args=st.lists(ARG_TOKENS, max_size=6))
def test_rtt_run_command_lines_end_in_a_status(tmp_path_factory, monkeypatch, args):
    """``rtt-run`` with generated arguments and no project file that exists: it stops before ROS starts."""
    from tutorial.tools import rtt_run

    monkeypatch.chdir(tmp_path_factory.mktemp("cwd"))
    args = [a for a in args if a not in ("/dev/zero", ".")] + ["missing.yaml"]
    assert exit_status(rtt_run.main, ["rtt-run", *args]) in (0, 2)


def test_found_by_fuzzing_a_name_that_is_not_utf8_gives_one_line(tmp_path):
    """``make fuzz`` found it: MuJoCo loads a name with a byte that is not UTF-8, and Python then fails to
    read the name back (a UnicodeDecodeError traceback from rtt-run)."""
    path = tmp_path / "m.xml"
    path.write_bytes((MODEL / "tank.xml").read_bytes().replace(b'name="TURRET_P"', b'name="\x80TURRET_P"', 1))
    with pytest.raises(ModelError, match=r"not UTF-8 text \(byte \d+\)") as info:
        build_world([ModelEntry("M", path)])
    assert one_line(info.value) and str(info.value).startswith(str(path))
