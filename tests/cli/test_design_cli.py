"""softbend design find: the ranked answers, their files, and one line for bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from softbend._outdir import MANIFEST, write_manifest
from softbend.cli import main

FIXED = ["--fix", "r=8", "--fix", "t=3", "--fix", "b=3", "--fix", "phi=10", "--fix", "lc=10"]


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    from tests.design_search.conftest import save_model

    return save_model(tmp_path_factory.mktemp("cli") / "linear.json")


def test_find_prints_json_and_writes_its_files(model, tmp_path, capsys):
    out = tmp_path / "design"
    args = ["design", "find", "--model", str(model), "--angle", "90", "--at", "0.08",
            "--minimize", "l", *FIXED, "--out", str(out), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    first = payload["candidates"][0]
    assert first["design"] == {"l": 109.0, "r": 8.0, "t": 3.0, "b": 3.0, "phi": 10.0, "lc": 10.0}
    assert first["angle_deg"] == pytest.approx(87.2, abs=1e-3) and first["meets"] is True
    for name in ("candidates.csv", "search.json", "front.png", "curves.png"):
        assert (out / name).is_file(), name
    assert main(args) == 0  # its own earlier results are replaced
    capsys.readouterr()


def test_a_table_on_the_terminal_and_a_spec_file_of_several(model, tmp_path, capsys):
    spec = tmp_path / "specs.toml"
    spec.write_text(
        '[[spec]]\nname = "short"\nangle = 90.0\nat = 0.08\nminimize = ["l"]\n'
        '[[spec]]\nname = "far"\nmax_angle_at = 0.05\n'
    )
    out = tmp_path / "many"
    assert main(["design", "find", "--model", str(model), "--spec", str(spec), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "short: 90° ± 3° at 0.08 MPa" in text and "far: the largest angle" in text
    assert (out / "short" / "candidates.csv").is_file() and (out / "far" / "front.png").is_file()
    assert len(json.loads((out / "search.json").read_text())["specs"]) == 2


def test_no_design_meets_it_is_a_warning_with_the_closest(model, tmp_path, capsys):
    args = ["design", "find", "--model", str(model), "--angle", "200", "--at", "0.08", *FIXED,
            "-o", str(tmp_path / "none"), "--json"]  # fmt: skip
    assert main(args) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["feasible"] is False
    assert (
        "No design in the ranges searched meets" in captured.err
        and "160,8,3,3,10,10" in captured.err
    )


@pytest.fixture(scope="module")
def short_model(tmp_path_factory):
    """θ = 10·p·l, the 160 mm designs swept to 0.05 MPa only."""
    from tests.design_search.conftest import save_model

    return save_model(
        tmp_path_factory.mktemp("cli") / "short.json",
        swept_to=lambda design: 0.05 if design[0] == 160.0 else 0.5,
    )


def _largest_at_008(short_model, out, *extra):
    args = ["design", "find", "--model", str(short_model), "--max-angle-at", "0.08", *FIXED,
            "--top", "3", "-o", str(out), *extra]  # fmt: skip
    assert main(args) == 0


def test_a_design_outside_the_training_data_is_said_as_predict_says_it(
    short_model, tmp_path, capsys
):
    # Paper B's 160 mm designs were swept to 0.05 MPa: at 0.08 MPa the largest angle (1.28°/mm)
    # is an extrapolation, passed over by default and flagged when allowed.
    _largest_at_008(short_model, tmp_path / "inside", "--json")
    captured = capsys.readouterr()
    inside = json.loads(captured.out)["candidates"]
    assert all(c["supported"] is True and c["flags"] == [] for c in inside)
    assert inside[0]["design"]["l"] < 160.0 and "not trained there" not in captured.err
    _largest_at_008(short_model, tmp_path / "outside", "--json", "--allow-extrapolation")
    captured = capsys.readouterr()
    outside = json.loads(captured.out)["candidates"]
    assert outside[0]["design"]["l"] == 160.0
    assert outside[0]["supported"] is False and outside[0]["flags"]
    assert [c["supported"] for c in outside] == [not c["flags"] for c in outside]
    assert "#1" in captured.err and "was not trained there" in captured.err
    _largest_at_008(short_model, tmp_path / "table", "--allow-extrapolation")
    captured = capsys.readouterr()
    assert "trained there" in captured.out
    rows = [line for line in captured.out.splitlines() if "160" in line and "0.08" not in line]
    assert rows and rows[0].rstrip(" │|").endswith("no"), captured.out


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        ([], "The target must be one of"),
        (["--angle", "90", "--at", "80"], "kPa"),
        (["--angle", "90", "--at", "0.08", "--minimize", "speed"], "--minimize"),
        (["--angle", "90", "--at", "0.08", "--range", "t=1:3"], "--allow-extrapolation"),
        (["--angle", "90", "--at", "0.08", "--fix", "wall=3"], "--fix"),
        (["--angle", "90", "--at", "0.08", "--resolution", "fine"], "--resolution"),
        (["--angle", "90", "--at", "0.08", "--top", "0"], "--top"),
        (["--angle", "90", "--at", "0.08", "--verify", "1", "--backend", "nope"], "--backend"),
    ],
)
def test_bad_input_is_one_line_exit_2(model, tmp_path, capsys, extra, needle):
    args = ["design", "find", "--model", str(model), "-o", str(tmp_path / "x"), *extra]
    assert main(args) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], captured.err
    assert not (tmp_path / "x").exists()


# --- softbend design find refuses, before any work and in one line, what it cannot do safely ---
#
# Nothing is written outside --out (a [[spec]] name is a plain folder name), a
# spec file is read under the TOML limits with every key checked, every number
# has a declared range, a search too large is counted before it is built, options
# that contradict each other are refused, the material is resolved before the
# search, and a killed verification leaves nothing the next run keeps.


FIXED_BIG = ["--fix", "r=8", "--fix", "t=3", "--fix", "b=3", "--fix", "phi=10", "--fix", "lc=10"]
TARGET = ["--angle", "90", "--at", "0.08"]

#: Words of Python's own exceptions that a message must never show.
PYTHON_WORDING = (
    "Traceback",
    "codec can't decode",
    "could not convert",
    "dictionary update sequence",
    "not enough values to unpack",
    "np.float64",
    "list index out of range",
    "RecursionError",
)


@pytest.fixture(scope="module")
def model_big(tmp_path_factory):
    from tests.design_search.conftest import save_model

    return save_model(tmp_path_factory.mktemp("limits") / "linear.json")


@pytest.fixture
def no_search(monkeypatch):
    """Fail the test if any design is scored."""

    def refuse(*args, **kwargs):
        raise AssertionError("a search started before every input was checked")

    monkeypatch.setattr("softbend.design_search.search.find_designs", refuse)


def _error(capsys) -> str:
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("softbend: error: "), lines[0]
    for words in PYTHON_WORDING:
        assert words not in lines[0], lines[0]
    return lines[0]


def _tree(root: Path) -> dict[str, tuple[bool, bytes | None, int]]:
    """Every path under ``root``: whether a folder, its bytes, its modification time."""
    out = {}
    for path in sorted(root.rglob("*")):
        stat = path.lstat()
        data = path.read_bytes() if path.is_file() else None
        out[str(path.relative_to(root))] = (path.is_dir(), data, stat.st_mtime_ns)
    return out


# -- 1. a [[spec]] name never becomes a path outside --out ---------------------------------

_GOOD = "angle = 90.0\nat = 0.08\nfix = {r = 8.0, t = 3.0, b = 3.0, phi = 10.0, lc = 10.0}\n"


def _table(name: str | None) -> str:
    line = "" if name is None else f"name = {json.dumps(name)}\n"
    return f"[[spec]]\n{line}{_GOOD}"


@pytest.mark.parametrize(
    ("names", "number", "needle"),
    [
        (["../../escaped_spec"], 1, "path separator"),
        (["../x"], 1, "path separator"),
        (["ABSOLUTE"], 1, "must be a plain name"),  # a path inside tmp_path
        (["/abs/x"], 1, "path separator"),
        ([""], 1, "is empty"),
        (["."], 1, "starts with '.'"),
        ([".."], 1, "starts with '.'"),
        (["a/b"], 1, "path separator"),
        (["ok", "../../escaped_spec"], 2, "path separator"),
        (["stiff", "stiff"], 2, "is given twice"),
        (["Stiff", "stiff"], 2, "only in case"),
        (["search.json", "other"], 1, "writes itself"),
        (["front.png", "other"], 1, "writes itself"),
        (["spec2", None], 2, "is given twice"),
    ],
)
def test_a_bad_spec_name_writes_nothing_anywhere(
    model_big, tmp_path, capsys, names, number, needle
):
    folder = tmp_path / "a" / "b"
    folder.mkdir(parents=True)
    victim = tmp_path / "escaped_spec" / "search.json"  # a user's file where ../../ points
    victim.parent.mkdir()
    victim.write_text("the user's notes\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "search.json").write_text('{"specs": []}\n')  # an earlier result, kept as it is
    write_manifest(out, "design find", complete=True)
    names = [str(tmp_path / "abs" / "x") if n == "ABSOLUTE" else n for n in names]
    spec = folder / "specs.toml"
    spec.write_text("".join(_table(n) for n in names), encoding="utf-8")
    before = _tree(tmp_path)
    args = ["design", "find", "--model", str(model_big), "--spec", str(spec), "--out", str(out)]
    assert main(args) == 2
    line = _error(capsys)
    assert needle in line and f"[[spec]] {number}" in line and str(spec) in line
    assert _tree(tmp_path) == before


def test_two_good_names_each_get_their_folder(model_big, tmp_path, capsys):
    spec = tmp_path / "specs.toml"
    spec.write_text(_table("short one") + _table(None), encoding="utf-8")
    out = tmp_path / "out"
    assert (
        main(["design", "find", "--model", str(model_big), "--spec", str(spec), "-o", str(out)])
        == 0
    )
    capsys.readouterr()
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "search.json", "short one", "spec2"]


# -- 2. a spec file is read under the limits, every key checked ------------------------------


def _deep_array() -> str:
    return "[[spec]]\nat = 0.08\nangle = " + "[" * 20_000 + "]" * 20_000 + "\n"


def _deep_table() -> str:
    return "[[spec]]\nat = 0.08\nangle = " + "{a = " * 3_000 + "1" + "}" * 3_000 + "\n"


@pytest.mark.parametrize(
    ("content", "needles"),
    [
        (_deep_array(), ["line 3", "nested 20,000 levels", "'angle'"]),
        (_deep_table(), ["line 3", "nested 3,000 levels", "'angle'"]),
        (b"\x80\x81[[spec]]\n", ["not UTF-8 text"]),
        ("[[spec]]\nangle = 90\nat = 0.08\n".encode("utf-16"), ["not UTF-8 text"]),
        ("[[spec]\n", ["line 1, column 7", "not valid TOML"]),
        ("[[spec]]\nangle = 90\nat = 0.08\nrange = {t = [3.0]}\n",
         ["[[spec]] 1 'range.t'", "[low, high]", "found an array of 1 [3.0]"]),
        ("[[spec]]\nangle = 90\nat = 0.08\ntolerance = 'wide'\n",
         ["[[spec]] 1 'tolerance'", "(0, 90] deg", "found the text 'wide'"]),
        ("[[spec]]\nangle = 90\nat = 0.08\nfix = ['a']\n",
         ["[[spec]] 1 'fix'", "a table of values by parameter", "found an array of 1"]),
        ("[[spec]]\ncurve = [[0.05], [0.1, 95.0]]\n",
         ["[[spec]] 1 'curve[1]'", "[pressure MPa, angle deg]", "found an array of 1"]),
        ("[[spec]]\ncurve = [[0.05, 40.0], [0.05, 50.0]]\n",
         ["[[spec]] 1 'curve[2]'", "0.05 MPa a second time"]),
        ("[[spec]]\nangle = 90\nat = 0.08\nrange = {t = [0.0, 1.0]}\n",
         ["[[spec]] 1 'range.t'", "(0, 50] mm", "found 0.0"]),
        ("[[spec]]\nangle = 90\nat = 80\n", ["[[spec]] 1 'at'", "(0, 1] MPa", "kPa", "found 80"]),
        ("[[spec]]\nangle = 90\nat = 0.08\n[[spec]]\nangle = 90\nat = 0.08\ncolour = 'red'\n",
         ["[[spec]] 2: unknown key(s) 'colour'", "the keys are name, angle, at"]),
        ("[[spec]]\nangle = 90\nat = 0.08\nminimize = ['l', 'speed']\n",
         ["[[spec]] 1 'minimize'", "among l, r, t", "found the text 'speed'"]),
        ("[[spec]]\nangle = 90\nat = 0.08\nresolution = {wall = 1.0}\n",
         ["[[spec]] 1 'resolution'", "among l, r, t, b, phi, lc", "'wall'"]),
        ("[[spec]]\nangle = 90\nat = 0.08\nmargin = 3.0\n",
         ["[[spec]] 1 'margin'", "[0, 3) deg", "found 3.0"]),
        ("[[spec]]\nangle = 90\nat = 0.08\nmax_angle_at = 0.1\n",
         ["[[spec]] 1", "exactly one target key", "'at' and 'max_angle_at'"]),
        ("[[spec]]\nat = 0.08\n", ["[[spec]] 1 'angle'", "expected with 'at'"]),
        ("title = 'mine'\n[[spec]]\nangle = 90\nat = 0.08\n", ["unknown key(s) 'title'"]),
        ("spec = 3\n", ["expected at least one [[spec]] table", "found 3"]),
        ("[[spec]]\nangle = 90\nat = 0.08\n" * 101, ["101 [[spec]] tables", "more than 100"]),
    ],
)  # fmt: skip
def test_a_bad_spec_file_is_one_line_naming_the_file_and_key(
    model_big, tmp_path, capsys, no_search, content, needles
):
    spec = tmp_path / "specs.toml"
    if isinstance(content, bytes):
        spec.write_bytes(content)
    else:
        spec.write_text(content, encoding="utf-8")
    out = tmp_path / "out"
    args = ["design", "find", "--model", str(model_big), "--spec", str(spec), "--out", str(out)]
    assert main(args) == 2
    line = _error(capsys)
    assert str(spec) in line
    for needle in needles:
        assert needle in line, line
    assert not out.exists()


# -- 3. every number has a range, a search's size is counted first ---------------------------


@pytest.mark.parametrize(
    ("extra", "needles"),
    [
        (["--resolution", "1e-9"], ["designs", "--resolution", "20,000,000"]),
        (["--resolution", "l=1e-9", "--range", "l=100:160"], ["l 60,000,000,001 at 1e-09 mm"]),
        (["--resolution", "inf"], ["--resolution: ", "finite"]),
        (["--top", "1000000000"], ["--top: ", "[1, 1000]"]),
        (["--top", "0"], ["--top: ", "[1, 1000]"]),
        (["--resolution", "l=0", "--top", "26"], ["--top: must be at most 25", "(l: step 0"]),
        (["--tolerance", "0"], ["--tolerance: ", "(0, 90] deg"]),
        (["--tolerance", "nan"], ["--tolerance: "]),
        (["--tolerance", "1000"], ["--tolerance: "]),
        (["--margin", "3"], ["--margin: ", "[0, 3)"]),
        (["--margin", "-1"], ["--margin: "]),
        (["--verify", "101"], ["--verify: ", "[0, 100]"]),
        (["--verify", "-1"], ["--verify: "]),
        (["--verify", "1", "--workers", "0"], ["--workers: ", "[1, 4096]"]),
        (["--verify", "1", "--workers", "100000"], ["--workers: ", "[1, 4096]"]),
        (["--range", "t=0:1", "--allow-extrapolation"], ["--range: t: leaves", "(0, 50] mm"]),
        (["--fix", "phi=90", "--allow-extrapolation"], ["--fix: phi: leaves", "[0, 60] deg"]),
    ],
)
def test_a_number_out_of_its_range_is_refused_before_the_search(
    model_big, tmp_path, capsys, no_search, extra, needles
):
    args = [
        "design",
        "find",
        "--model",
        str(model_big),
        *TARGET,
        "--out",
        str(tmp_path / "x"),
        *extra,
    ]
    assert main(args) == 2
    line = _error(capsys)
    for needle in needles:
        assert needle in line, line
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    ("target", "needles"),
    [
        (["--curve", "0.05:40,0.05:50"], ["--curve: gives 0.05 MPa twice", "each pressure once"]),
        (["--curve", "0:40,0.05:50"], ["--curve: point '0:40'", "(0, 1] MPa"]),
        (["--curve", "nan:40,0.05:50"], ["--curve: point 'nan:40'"]),
        (["--curve", "0.05:40,0.1:400"], ["--curve: point '0.1:400'", "(0, 360] deg"]),
        (["--curve", ",".join(f"{0.01 * i:.2f}:{i}" for i in range(1, 60))], ["2 to 50 points"]),
        (["--curve", "0.05:40,0.1:90", "--angle", "10"], ["--angle: has no meaning"]),
        (["--angle", "400", "--at", "0.08"], ["--angle: ", "(0, 360] deg"]),
        (["--angle", "90", "--at", "inf"], ["--at: ", "MPa"]),
        (["--angle", "90", "--max-pressure", "-1"], ["--max-pressure: ", "(0, 1] MPa"]),
        (["--max-angle-at", "2"], ["--max-angle-at: ", "kPa"]),
    ],
)
def test_a_bad_target_is_refused_before_the_search(
    model_big, tmp_path, capsys, no_search, target, needles
):
    args = ["design", "find", "--model", str(model_big), *target, "--out", str(tmp_path / "x")]
    assert main(args) == 2
    line = _error(capsys)
    for needle in needles:
        assert needle in line, line


# -- 4. the verification's options and material, before any search ---------------------------


@pytest.fixture(scope="module")
def fit_json(tmp_path_factory):
    out = tmp_path_factory.mktemp("fit")
    assert main(["materials", "fit", "--out", str(out), "--json"]) == 0
    return out / "fit.json"


def test_the_material_is_resolved_before_the_search(
    model_big, tmp_path, capsys, no_search, fit_json
):
    not_json = tmp_path / "fit.json"
    not_json.write_text("{ not json", encoding="utf-8")
    negative = tmp_path / "negative.json"
    data = json.loads(fit_json.read_text(encoding="utf-8"))
    next(f for f in data["fits"] if f["model"] == "yeoh")["parameters"]["c10_mpa"] = -0.1
    negative.write_text(json.dumps(data), encoding="utf-8")
    base = ["design", "find", "--model", str(model_big), *TARGET, "--out", str(tmp_path / "x")]
    for material, needle in (
        ("nope", "Unknown material preset 'nope'"),
        (str(not_json), "not valid JSON"),
        (f"{negative}#yeoh", "c10_mpa"),
    ):
        assert main([*base, "--verify", "1", "--material", material]) == 2
        assert needle in _error(capsys)
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    "extra",
    [
        ["--workers", "2"],
        ["--material", "dragon-skin-30"],
        ["--backend", "analytical"],
        ["--replace-stopped"],
    ],
)
def test_a_verification_option_without_verify_is_refused(
    model_big, tmp_path, capsys, no_search, extra
):
    args = ["design", "find", "--model", str(model_big), *TARGET, "-o", str(tmp_path / "x"), *extra]
    assert main(args) == 2
    assert f"{extra[0]}: applies to the verification; give --verify N" in _error(capsys)


# -- 5. options that the spec file gives ------------------------------------------------------


@pytest.mark.parametrize(
    ("extra", "flag", "what"),
    [
        (["--angle", "10", "--at", "0.01"], "--angle", "target"),
        (["--at", "0.01"], "--at", "target"),
        (["--max-angle-at", "0.1"], "--max-angle-at", "target"),
        (["--curve", "0.05:40,0.1:90"], "--curve", "target"),
        (["--tolerance", "2"], "--tolerance", "tolerance"),
        (["--margin", "1"], "--margin", "margin"),
        (["--minimize", "l"], "--minimize", "objectives"),
        (["--maximize", "angle"], "--maximize", "objectives"),
        (["--fix", "phi=10"], "--fix", "ranges"),
        (["--range", "t=3:4"], "--range", "ranges"),
        (["--resolution", "1"], "--resolution", "resolution"),
    ],
)
def test_an_option_the_spec_file_gives_is_refused_beside_it(
    model_big, tmp_path, capsys, no_search, extra, flag, what
):
    spec = tmp_path / "specs.toml"
    spec.write_text(_table("one"), encoding="utf-8")
    args = [
        "design",
        "find",
        "--model",
        str(model_big),
        "--spec",
        str(spec),
        "-o",
        str(tmp_path / "x"),
    ]
    assert main([*args, *extra]) == 2
    line = _error(capsys)
    assert f"{flag}: cannot be used with --spec: the spec file gives each spec's {what}" in line


# -- 6. the verification's temporary campaign after a kill ------------------------------------


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_the_verification_s_campaign_is_kept_beside_out_until_the_run_ends(
    model_big, tmp_path, capsys, monkeypatch
):
    """Beside --out, so that an interrupted run keeps its sweeps; a finished run removes it,
    and the staging folder a killed run left is cleared."""
    import softbend.campaign

    out = tmp_path / "design"
    stale = tmp_path / f".design.{_dead_pid()}-killed.new"  # a run killed with -9
    (stale / "softbend-verify-left").mkdir(parents=True)
    (stale / "softbend-verify-left" / "verify.duckdb").write_bytes(b"campaign of a dead run")
    pid = int(stale.name.split(".")[2].split("-")[0])
    manifest = {"format": "softbend-output-manifest", "version": 1, "command": "design find",
                "pid": pid, "complete": False, "entries": {}}  # fmt: skip
    (stale / MANIFEST).write_text(json.dumps(manifest))  # what a staging folder starts with
    used: list[Path] = []
    original = softbend.campaign.run_campaign

    def recording(db_path, *args, **kwargs):
        used.append(Path(db_path))
        return original(db_path, *args, **kwargs)

    monkeypatch.setattr(softbend.campaign, "run_campaign", recording)
    args = ["design", "find", "--model", str(model_big), *TARGET, *FIXED_BIG, "--top", "2",
            "--verify", "1", "--backend", "analytical", "--workers", "1", "-o", str(out),
            "--json"]  # fmt: skip
    assert main(args) == 0
    capsys.readouterr()
    assert not stale.exists()
    (db,) = used
    assert db.parent == tmp_path
    assert db.name.startswith(".design.verify-") and db.name.endswith(".duckdb")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design"]
    assert sorted(p.name for p in out.iterdir()) == [
        MANIFEST, "candidates.csv", "curves.png", "front.png", "search.json"
    ]  # fmt: skip
    first = json.loads((out / "search.json").read_text())["candidates"][0]
    assert first["fem_meets"] is not None


def test_the_rounds_line_gives_each_round_s_fem_angles_and_whether_the_last_met():
    from softbend.cli.design import _rounds_line

    def record(number, *verified):
        return {
            "round": number,
            "verified": [{"fem_angle_deg": a, "fem_meets": m} for a, m in verified],
        }

    met = [record(0, (80.123, False), (None, False)), record(1, (90.59, True))]
    assert _rounds_line(met) == (
        "refined on the verification's sweeps 1 time(s); their angles by round: "
        "0: 80.12°, stopped; 1: 90.59° (the last within the tolerance)"
    )
    missed = [record(0, (64.61, False)), record(1, (102.67, False)), record(2, (78.69, False))]
    line = _rounds_line(missed)
    assert line.startswith("refined on the verification's sweeps 2 time(s)")
    assert line.endswith("2: 78.69° (none within the tolerance)")
