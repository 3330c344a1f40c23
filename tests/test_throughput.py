"""The speed benchmark still runs (quick mode; no thresholds: timing is for
benchmarks/speed.py, ``arcosim bench speed``, on a quiet machine, not for CI)."""

from __future__ import annotations

import json

import pytest

from arcosim.cli import main


@pytest.mark.slow
def test_speed_benchmark_runs_in_quick_mode(build_fmus, tmp_path, monkeypatch, capsys) -> None:
    folder = build_fmus(3)
    monkeypatch.setattr("benchmarks.speed.ensure_built", lambda n=3: build_fmus(n))
    assert main(["bench", "speed", "--quick", "--out", str(tmp_path)]) == 0
    table = (tmp_path / "throughput.md").read_text()
    for row in ("whole loop", "observer doStep", "plain Python", "| 1 s |", "Output-error"):
        assert row in table
    figures = json.loads((tmp_path / "throughput.json").read_text())
    loop = figures["bench_loop_us"]
    assert 0.0 < loop["low"] <= loop["median"] <= loop["high"]
    assert set(figures["loop_us_by_masses"]) == {"1", "3"}
    assert figures["output_error_10s_seconds"]["median"] > 0.0
    assert "wrote" in capsys.readouterr().out
    assert (folder / "MotorChainPlant.fmu").is_file()
