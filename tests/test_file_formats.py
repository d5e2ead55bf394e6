"""Property-based tests over every file format softbend reads.

Each reader gets valid files with random damage (fields replaced by absurd or
malformed values, lines dropped, duplicated or cut, bytes of another format) and
plain random text. Whatever the input, a reader either returns or raises one of
softbend's own errors (:class:`~softbend.errors.SoftbendError`), which the CLI
prints as one line: never a ``KeyError``, ``TypeError``, ``RecursionError`` or a
library's own exception. The examples are derandomized (the same inputs on every
run) and bounded, so the suite is quick; the number of inputs tried per format is
printed in the test summary.
"""

from __future__ import annotations

import contextlib
import copy
import json
import shutil
from importlib import resources
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from softbend.errors import SoftbendError

EXAMPLES = 150
SETTINGS = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)

#: Field values that break naive readers.
NASTY = [
    "",
    " ",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e300",
    "-1e300",
    "1e-320",
    "-0",
    "abc",
    '"',
    "'",
    ";",
    ",",
    "=",
    "[",
    "{",
    "0x1F",
    "99999999999999999999999999",
    "1,5",
    "true",
    "null",
    "\u00e9\u00e8",
    "\x00",
    "#",
    "# synthetic: maybe",
    "-1",
    "1e6",
]


def _data(*parts: str) -> Path:
    return Path(str(resources.files("softbend").joinpath("data", *parts)))


@st.composite
def damaged_text(draw: st.DrawFn, seed: str) -> str:
    """``seed`` with one to four random edits, or random text."""
    if draw(st.integers(0, 9)) == 0:
        return draw(st.text(max_size=200))
    lines = seed.splitlines()
    for _ in range(draw(st.integers(1, 4))):
        if not lines:
            lines = [""]
        i = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["field", "field", "field", "drop", "dup", "cut", "insert"]))
        if kind == "field":
            sep = next((s for s in (",", ";", "=", ":") if s in lines[i]), None)
            value = draw(st.sampled_from(NASTY) | st.text(max_size=8))
            if sep is None:
                lines[i] = value
            else:
                fields = lines[i].split(sep)
                j = draw(st.integers(0, len(fields) - 1))
                fields[j] = value
                lines[i] = sep.join(fields)
        elif kind == "drop":
            del lines[i]
        elif kind == "dup":
            lines.insert(i, lines[i])
        elif kind == "cut":
            lines = lines[: i + 1]
            lines[-1] = lines[-1][: draw(st.integers(0, max(len(lines[-1]), 0)))]
        else:
            lines.insert(i, draw(st.sampled_from(NASTY) | st.text(max_size=20)))
    return "\n".join(lines) + draw(st.sampled_from(["\n", ""]))


def _nasty_json() -> st.SearchStrategy:
    leaves = st.sampled_from(
        [
            None,
            True,
            False,
            0,
            -1,
            1e308,
            -1e308,
            float("nan"),
            float("inf"),
            "",
            "x",
            "nan",
            1e-320,
        ]
    )
    return st.recursive(
        leaves,
        lambda inner: (
            st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=4), inner, max_size=3)
        ),
        max_leaves=6,
    )


def _paths(node: object, prefix: tuple = ()) -> list[tuple]:
    out = [prefix]
    if isinstance(node, dict):
        for key, value in node.items():
            out += _paths(value, (*prefix, key))
    elif isinstance(node, list):
        for k, value in enumerate(node[:5]):  # the first entries of long arrays suffice
            out += _paths(value, (*prefix, k))
    return out


@st.composite
def damaged_json(draw: st.DrawFn, seed: object) -> str:
    """``seed`` (a parsed JSON document) with one to three nodes replaced or removed."""
    if draw(st.integers(0, 9)) == 0:
        return draw(st.text(max_size=100))
    doc = copy.deepcopy(seed)
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(doc)
        path = draw(st.sampled_from(paths))
        if not path:
            doc = draw(_nasty_json())
            continue
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        if draw(st.booleans()) and isinstance(parent, dict):
            del parent[path[-1]]
        else:
            parent[path[-1]] = draw(_nasty_json())
    text = json.dumps(doc)
    if draw(st.integers(0, 19)) == 0 and text.endswith("}"):  # a field nested 5000 deep
        text = (
            text[:-1] + (", " if len(text) > 2 else "") + '"deep": ' + "[" * 5000 + "]" * 5000 + "}"
        )
    return text


def _only_own_errors(read, path: Path, counter, name: str) -> None:
    counter[name] += 1
    with contextlib.suppress(SoftbendError):  # the project's own error: one line on the CLI
        read(path)


# --- CSV formats ---------------------------------------------------------------------------


def _head(path: Path, lines: int) -> str:
    return "\n".join(path.read_text(encoding="utf-8").splitlines()[:lines]) + "\n"


MEASUREMENTS = _head(_data("transfer", "virtual_lab.csv"), 30)
TENSILE = _head(_data("materials", "Dragon_Skin_30.csv"), 40)
EXPERIMENTS = (
    "# synthetic: false\n# rest_length_mm: 15.25\ntime_s,pressure_kpa,x_mm,y_mm,experiment\n"
    + "".join(
        f"{0.02 * k:.2f},{10.0 * (k % 5)},{0.3 * (k % 5):.2f},{0.02 * (k % 5):.2f},e{k // 10}\n"
        for k in range(30)
    )
)


def _reader(name: str):
    if name == "measurements CSV":
        from softbend.transfer.measurements import load_measurements

        return load_measurements
    if name == "curling experiments CSV":
        from softbend.identification.data import load_experiments

        return load_experiments
    from softbend.materials.tensile import load_tensile_csv

    return load_tensile_csv


CSV_SEEDS = {
    "measurements CSV": MEASUREMENTS,
    "curling experiments CSV": EXPERIMENTS,
    "tensile CSV": TENSILE,
}


@pytest.mark.parametrize("name", list(CSV_SEEDS))
@SETTINGS
@given(data=st.data())
def test_csv_formats(tmp_path, fuzz_counter, name, data):
    path = tmp_path / "input.csv"
    text = data.draw(damaged_text(CSV_SEEDS[name]))
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _only_own_errors(_reader(name), path, fuzz_counter, name)


# --- TOML formats: rig files and design specifications ------------------------------------


@st.composite
def damaged_toml(draw: st.DrawFn, seed: str) -> str:
    """``seed`` damaged as text, now and then with a key nested thousands deep."""
    text = draw(damaged_text(seed))
    deep = draw(st.integers(0, 9))
    if deep == 0:  # an array 20 000 deep
        text += "\ndeep = " + "[" * 20_000 + "]" * 20_000 + "\n"
    elif deep == 1:  # an inline table 3 000 deep
        text += "\ndeep = " + "{a = " * 3_000 + "1" + "}" * 3_000 + "\n"
    elif deep == 2:  # tables nested by a dotted header
        text += "\n[" + ".".join(["t"] * draw(st.integers(60, 400))) + "]\nx = 1\n"
    return text


SPECS = """\
[[spec]]
name = "gripper finger"
angle = 90.0
at = 0.08
tolerance = 3.0
minimize = ["l"]
fix = {phi = 10.0}
range = {t = [3.0, 4.0]}
resolution = 0.5

[[spec]]
name = "stiff"
max_angle_at = 0.1
maximize = ["angle"]
resolution = {l = 1.0}

[[spec]]
name = "curve"
curve = [[0.05, 40.0], [0.1, 95.0]]
"""


@SETTINGS
@given(data=st.data())
def test_design_spec_toml(tmp_path, fuzz_counter, data):
    from softbend.design_search.spec_toml import load_specifications

    text = data.draw(damaged_toml(SPECS))
    path = tmp_path / "specs.toml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _only_own_errors(load_specifications, path, fuzz_counter, "design spec TOML")


@SETTINGS
@given(data=st.data())
def test_rig_toml(tmp_path, fuzz_counter, data):
    from softbend.control.rigconfig import RigConfig, load_rig_config

    text = data.draw(damaged_toml(RigConfig().to_toml()))
    path = tmp_path / "rig.toml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _only_own_errors(load_rig_config, path, fuzz_counter, "rig TOML")


# --- model JSON formats --------------------------------------------------------------------


def _surrogate_file(folder: Path) -> Path:
    """A small saved surrogate (a degree-2 polynomial)."""
    import numpy as np

    from softbend.surrogates.persistence import save_surrogate
    from softbend.surrogates.polynomial import PolynomialRegressor

    rng = np.random.default_rng(0)
    X = rng.uniform([100, 6, 2, 2, 5, 8, 0], [160, 10, 4, 4, 15, 12, 0.3], size=(60, 7))
    model = PolynomialRegressor(degree=2).fit(X, 300 * X[:, 6] + 0.1 * X[:, 0])
    return save_surrogate(model, folder / "plr.json")


def _narx_file(folder: Path) -> Path:
    """A small saved NARX model of paper A's identification."""
    import numpy as np

    from softbend.identification.narx import NARXRegressor
    from softbend.identification.persistence import save_narx
    from softbend.identification.svr import GeneralizedGaussianSVR

    u = np.repeat(np.random.default_rng(0).uniform(-1, 1, 12), 5)[:, None]
    model = NARXRegressor(estimator=GeneralizedGaussianSVR(epsilon=0.05))
    return save_narx(model.fit(u, np.tanh(np.cumsum(u[:, 0]) * 0.1)), folder / "narx.json")


def _fit_file(folder: Path) -> Path:
    """The fit.json of the shipped Dragon Skin 30 test."""
    from softbend.cli import main

    assert main(["materials", "fit", "--out", str(folder), "--json"]) == 0
    return folder / "fit.json"


def _json_loader(name: str):
    if name == "surrogate model JSON":
        from softbend.surrogates.persistence import load_surrogate

        return load_surrogate
    if name == "NARX model JSON":
        from softbend.identification.persistence import load_narx

        return load_narx
    from softbend.materials.fit import load_fit_json

    return load_fit_json


JSON_SEEDS = {
    "surrogate model JSON": _surrogate_file,
    "NARX model JSON": _narx_file,
    "material fit JSON": _fit_file,
}


@pytest.fixture(scope="module")
def json_seeds(tmp_path_factory) -> dict[str, object]:
    """Each model format's seed document, parsed."""
    return {
        name: json.loads(write(tmp_path_factory.mktemp("seed")).read_text(encoding="utf-8"))
        for name, write in JSON_SEEDS.items()
    }


@pytest.mark.parametrize("name", list(JSON_SEEDS))
@SETTINGS
@given(data=st.data())
def test_model_json_formats(tmp_path, fuzz_counter, json_seeds, name, data):
    path = tmp_path / "model.json"
    path.write_text(data.draw(damaged_json(json_seeds[name])), encoding="utf-8")
    _only_own_errors(_json_loader(name), path, fuzz_counter, name)


# --- shipped-dataset provenance ------------------------------------------------------------


@pytest.fixture(scope="module")
def dataset_copy(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("dataset") / "table1_fem"
    shutil.copytree(_data("table1_fem"), folder)
    return folder


@SETTINGS
@given(data=st.data())
def test_dataset_provenance_json(fuzz_counter, dataset_copy, data):
    from softbend.datasets import table1_fem

    provenance = dataset_copy / "provenance.json"
    original = json.loads(_data("table1_fem", "provenance.json").read_text(encoding="utf-8"))
    provenance.write_text(data.draw(damaged_json(original)), encoding="utf-8")
    _only_own_errors(table1_fem, dataset_copy, fuzz_counter, "dataset provenance JSON")
