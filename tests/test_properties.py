"""Property-based tests (hypothesis) of what enters the command line.

Arbitrary text, numbers and bytes go to the log reader, the ``--set`` parser and the
sweep spec loader, directly and through ``arcosim``. Each either gives a valid result
(the checks of a good log, typed values in their FMI ranges, a spec within its
limits) or refuses with one line (:class:`UserError`; exit 2) — never a traceback,
never a changed input file.
"""

from __future__ import annotations

import math
import string
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from arcosim.cli import main
from arcosim.errors import UserError
from arcosim.logs import LOG_COLUMNS, read_log
from arcosim.sweeps.spec import DISTRIBUTIONS

FAST = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
#: Through the command line: each example runs the FMUs, so fewer.
SLOW = settings(
    max_examples=12,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)


def one_line(error: UserError) -> str:
    text = str(error)
    assert "\n" not in text and "\r" not in text, text
    assert "Traceback" not in text and "np.float64" not in text, text
    return text


def written(data: bytes, name: str) -> tuple[Path, tempfile.TemporaryDirectory]:
    folder = tempfile.TemporaryDirectory(prefix="arcosim-prop-")
    path = Path(folder.name) / name
    path.write_bytes(data)
    return path, folder


def check_cli(capsys, argv: list[str]) -> int:
    """``arcosim ARGV``: 0, or 2 with one line on stderr; never a traceback."""
    code = main(argv)
    err = capsys.readouterr().err
    assert code in (0, 2), err
    assert "Traceback" not in err and "np.float64" not in err, err
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("arcosim: error: "), err
    return code


# -- the log reader ---------------------------------------------------------------------

NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**30), 10**30).map(str),
    st.sampled_from(["", " ", "nan", "inf", "-inf", "1e999", "1_0", "0x10", "1,5", "１"]),
    st.text(max_size=8),
)
CELLS = st.one_of(NUMBERS, st.text(string.printable, max_size=6))


@st.composite
def csv_logs(draw) -> bytes:
    """A CSV-like text: a header of (mostly) the log's columns, rows of number-ish cells."""
    names = draw(
        st.lists(
            st.one_of(
                st.sampled_from([*LOG_COLUMNS, "x", "time ", "\ufefftime"]), st.text(max_size=5)
            ),
            max_size=7,
        )
    )
    rows = draw(st.lists(st.lists(CELLS, max_size=len(names) + 1), max_size=6))
    separator = draw(st.sampled_from([",", ";", "\t"]))
    newline = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    text = newline.join(separator.join(r) for r in [names, *rows])
    encoding = draw(st.sampled_from(["utf-8", "utf-8-sig", "latin-1", "utf-16"]))
    return text.encode(encoding, "replace")


@st.composite
def increasing_logs(draw) -> bytes:
    """A log that should be read: increasing finite times, finite values."""
    count = draw(st.integers(2, 8))
    steps = draw(st.lists(st.floats(1e-6, 10.0), min_size=count - 1, max_size=count - 1))
    start = draw(st.floats(-1e3, 1e3))
    times = start + np.concatenate([[0.0], np.cumsum(steps)])
    values = draw(st.lists(st.floats(-1e6, 1e6), min_size=3 * count, max_size=3 * count))
    lines = ["time,i_a,omega_m,theta_m"]
    for k, t in enumerate(times):
        lines.append(",".join(repr(float(x)) for x in (t, *values[3 * k : 3 * k + 3])))
    return ("\n".join(lines) + "\n").encode()


def check_read(data: bytes, scales: dict[str, float] | None = None) -> None:
    path, folder = written(data, "log.csv")
    with folder:
        try:
            log = read_log(path, scales)
        except UserError as error:
            assert one_line(error).startswith(str(path)), error
        else:
            assert len(log) >= 2
            assert np.all(np.diff(log.time) > 0)
            assert all(np.all(np.isfinite(log.columns[c])) for c in LOG_COLUMNS)
        assert path.read_bytes() == data  # the input is never changed


@FAST
@given(st.binary(max_size=300))
def test_log_reader_on_bytes(data: bytes) -> None:
    check_read(data)


@pytest.mark.slow
@settings(FAST, max_examples=80)
@given(csv_logs())
def test_log_reader_on_csv_like_text(data: bytes) -> None:
    check_read(data)


@FAST
@given(
    increasing_logs(),
    st.dictionaries(
        st.sampled_from(LOG_COLUMNS),
        st.floats(allow_nan=False, allow_infinity=False).filter(lambda x: x != 0),
        max_size=4,
    ),
)
def test_log_reader_reads_good_logs_and_scales_them(data: bytes, scales) -> None:
    path, folder = written(data, "log.csv")
    with folder:
        try:
            log = read_log(path, scales)
        except UserError as error:  # only a scale that overflows, or a step lost to it
            assert "once scaled" in one_line(error) or "does not increase" in str(error)
            assert scales
        else:
            raw = np.loadtxt(path, delimiter=",", skiprows=1)
            for j, c in enumerate(LOG_COLUMNS):
                np.testing.assert_array_equal(log.columns[c], raw[:, j] * scales.get(c, 1.0))


def test_identify_on_arbitrary_logs(capsys, build_fmus) -> None:
    fmus = str(build_fmus(3))
    codes = []

    @SLOW
    @given(data=st.one_of(csv_logs(), increasing_logs(), st.binary(max_size=200)))
    def check(data: bytes) -> None:
        path, folder = written(data, "log.csv")
        with folder:
            codes.append(check_cli(capsys, ["identify", str(path), "--fmus", fmus, "--json"]))
            assert path.read_bytes() == data

    check()
    assert 2 in codes, codes


# -- the --set parser ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def variables(build_fmus):
    from arcosim.build.builder import fmu_variables

    return fmu_variables(build_fmus(3))


def parameter_names(variables) -> list[str]:
    return sorted(
        f"{fmu}.{name}"
        for fmu, found in variables.items()
        for name, v in found.items()
        if v.causality == "parameter"
    )


VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(2**70), 2**70).map(str),
    st.booleans().map(str),
    st.sampled_from(["true", "off", "", " 3 ", "1e-400", "2.5", "1e3", "\x00", "\udcff"]),
    st.text(max_size=10),
)


#: Values a parameter may well take: the half of the examples that should often run.
PLAUSIBLE = st.one_of(
    st.floats(1e-6, 1e3).map(repr), st.integers(0, 3).map(str), st.sampled_from(["true", "0"])
)


@st.composite
def assignments(draw, names: list[str]) -> str:
    if draw(st.booleans()):
        return f"{draw(st.sampled_from(names))}={draw(PLAUSIBLE)}"
    name = draw(st.one_of(st.sampled_from(names), st.text(max_size=12)))
    sep = draw(st.sampled_from(["=", "=", "==", ":", ""]))
    return f"{name}{sep}{draw(VALUES)}"


def test_set_parser_types_or_refuses(variables) -> None:
    from arcosim.host.overrides import INT_MAX, INT_MIN, split_overrides

    names = parameter_names(variables)

    @FAST
    @given(st.lists(assignments(names), max_size=4))
    def check(texts: list[str]) -> None:
        try:
            result = split_overrides(texts, variables)
        except UserError as error:
            one_line(error)
            return
        for fmu, values in result.items():
            for name, value in values.items():
                vtype = variables[fmu][name].type
                if vtype == "Real":
                    assert isinstance(value, float) and math.isfinite(value)
                elif vtype == "Integer":
                    assert isinstance(value, int) and INT_MIN <= value <= INT_MAX
                elif vtype == "Boolean":
                    assert isinstance(value, bool)
                else:
                    assert isinstance(value, str) and "\x00" not in value
                    value.encode("utf-8")

    check()


def test_simulate_with_arbitrary_settings(capsys, build_fmus, variables) -> None:
    names = [n for n in parameter_names(variables) if not n.endswith("trace_file")]
    folder = str(build_fmus(3))

    codes = []

    @settings(SLOW, max_examples=20)
    @given(st.lists(assignments(names), min_size=1, max_size=2))
    def check(texts: list[str]) -> None:
        argv = ["simulate", "--fmus", folder, "--duration", "0.02", "--json"]
        for text in texts:
            argv += ["--set", text]
        codes.append(check_cli(capsys, argv))

    check()
    assert 0 in codes and 2 in codes, codes  # both outcomes were exercised


# -- the sweep spec loader ------------------------------------------------------------------


def toml_string(text: str) -> str:
    escaped = "".join(c if c.isprintable() and c not in '"\\' else f"\\u{ord(c):04x}" for c in text)
    return f'"{escaped}"'


SCALARS = st.one_of(
    st.integers(-(2**64), 2**64).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(
        lambda x: (
            "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf") if math.isinf(x) else repr(x)
        )
    ),
    st.booleans().map(lambda b: "true" if b else "false"),
    st.text(max_size=12).map(toml_string),
    st.sampled_from(['"../../x"', '"ten"', '"abc"', '"rigid"', '"selfid"', "1979-05-27"]),
)
LITERALS = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=3).map(lambda xs: "[" + ", ".join(xs) + "]"),
        st.dictionaries(
            st.sampled_from(["distribution", "low", "high", "mean", "std", "values", "x"]),
            inner,
            max_size=4,
        ).map(lambda d: "{ " + ", ".join(f"{k} = {v}" for k, v in d.items()) + " }"),
    ),
    max_leaves=6,
)
#: The spec's distributions and the keys each takes, and one kind the spec does not know.
PARAMETERS = {**DISTRIBUTIONS, "wobbly": ("low",)}


@st.composite
def distributions(draw) -> str:
    """An inline table: a distribution with its parameters (some missing, some extra)."""
    kind = draw(st.sampled_from(sorted(PARAMETERS)))
    parts = [f'distribution = "{kind}"']
    for key in PARAMETERS[kind]:
        if draw(st.integers(0, 9)):  # now and then a parameter is missing
            value = draw(st.lists(SCALARS, max_size=4).map(lambda xs: "[" + ", ".join(xs) + "]"))
            parts.append(f"{key} = {value if key == 'values' else draw(SCALARS)}")
    if not draw(st.integers(0, 9)):
        parts.append(f"extra = {draw(SCALARS)}")
    return "{ " + ", ".join(parts) + " }"


@st.composite
def specs(draw) -> bytes:
    keys = ["name", "scenario", "masses", "runs", "seed", "metrics", "duration", "step", "ideal"]
    lines = [
        f"{key} = {draw(LITERALS)}"
        for key in draw(st.lists(st.sampled_from([*keys, "colour"]), unique=True, max_size=6))
    ]
    for table in draw(st.lists(st.sampled_from(["fixed", "vary"]), unique=True)):
        lines.append(f"[{table}]")
        for _ in range(draw(st.integers(0, 2))):
            name = draw(st.sampled_from(['"observer.g_dist"', '"plant.seed"', '"g_dist"', "x"]))
            value = draw(distributions() if table == "vary" else LITERALS)
            lines.append(f"{name} = {value}")
    text = "\n".join(lines) + "\n"
    return text.encode(draw(st.sampled_from(["utf-8", "utf-8-sig", "latin-1"])), "replace")


def check_spec(data: bytes) -> None:
    from arcosim.sweeps.spec import MAX_RUNS, METRICS, NAME, draw_runs, load_spec

    path, folder = written(data, "spec.toml")
    with folder:
        try:
            spec = load_spec(path)
        except UserError as error:
            assert one_line(error).startswith(str(path)), error
        else:
            assert NAME.fullmatch(spec.name) and spec.name not in (".", "..")
            assert isinstance(spec.runs, int) and 1 <= spec.runs <= MAX_RUNS
            assert isinstance(spec.seed, int) and spec.seed >= 0
            assert 1 <= spec.masses <= 20 and set(spec.metrics) <= set(METRICS)
            assert spec.duration is None or (math.isfinite(spec.duration) and spec.duration > 0)
            assert math.isfinite(spec.step) and spec.step > 0
            if spec.runs <= 1000:
                assert len(draw_runs(spec)) == spec.runs
        assert path.read_bytes() == data


@FAST
@given(st.binary(max_size=300))
def test_spec_loader_on_bytes(data: bytes) -> None:
    check_spec(data)


@pytest.mark.slow
@settings(FAST, max_examples=200)
@given(specs())
def test_spec_loader_on_toml_of_every_type(data: bytes) -> None:
    check_spec(data)


def test_spec_loader_accepts_what_it_should() -> None:
    """The generated specs are not all refusals: a valid one among the field types."""
    valid = (
        b'name = "ok"\nscenario = "selfid"\nruns = 3\nseed = 0\nduration = 0.5\n'
        b'[vary]\n"observer.g_dist" = { distribution = "uniform", low = 1.0, high = 2.0 }\n'
    )
    check_spec(valid)
    from arcosim.sweeps.spec import load_spec

    path, folder = written(valid, "spec.toml")
    with folder:
        assert load_spec(path).runs == 3
