"""The accuracy benchmark's rows count the library's verdict: ``trusted k of N`` per row,
and each untrusted seed's reasons kept by seed, also when runs made in parts are merged."""

from __future__ import annotations

import json
from pathlib import Path

from benchmarks import chain_accuracy, field_accuracy

ROW = "closely spaced modes"


def _run(seed: int, reasons: list[str]) -> dict:
    """One record's numbers as ``score_log`` writes them: n right, the errors and σ (%)."""
    n = field_accuracy.ROWS[ROW].drive.n
    out = {"seed": seed, "n": n, "seconds": 1.0, "cpu_seconds": 1.0, "stuck_fraction": 0.0}
    out.update({key: [0.1] * n for key in ("J", "k", "B")})
    out.update({key + "_std": [0.1] * n for key in ("J", "k", "B")})
    out.update(verdict="untrusted" if reasons else "trusted", reasons=reasons)
    return out


def test_a_field_row_counts_trusted_seeds_and_keeps_the_reasons_by_seed(tmp_path: Path) -> None:
    why = ["the residual is 5 × the noise floor: check k_t"]
    first = [_run(1, []), _run(2, why)]
    second = [_run(3, [])]
    for name, runs in (("a.json", first), ("b.json", second)):
        (tmp_path / name).write_text(json.dumps({"runs": {ROW: runs}}))
    merged = field_accuracy.merged([tmp_path / "a.json", tmp_path / "b.json"])[ROW]
    assert (merged["trusted"], merged["seeds"]) == (2, 3)
    assert merged["untrusted_reasons"] == {"2": why}
    assert "| 2 of 3 |" in field_accuracy.markdown({ROW: merged})


def test_the_chain_table_prints_the_verdict_count() -> None:
    row = {
        "seeds": 2,
        "trusted": 1,
        "right_n": 2,
        "J_error_percent": [[0.1]],
        "k_error_percent": [[0.1]],
        "B_error_percent": [[1.0]],
        "B_inside_2_sigma": [2],
        "B_count": 2,
        "seconds": [1.0, 2.0],
    }
    table = chain_accuracy.markdown({"two-mass": row})
    assert "| two-mass | 1 of 2 | 2 of 2 |" in table
    assert table.splitlines()[0].startswith("| chain | trusted | n right |")


def test_a_group_of_accuracy_rows_runs_alone_into_its_own_files(tmp_path: Path, monkeypatch):
    """``bench accuracy --beam-only`` / ``--load-torque-only`` / ``--whole-chain-only``: that
    group's table alone, on seeds 1 … max(seeds, b_seeds) (one in quick mode), written as
    ``STEM.md`` and ``STEM.json``."""
    from benchmarks import accuracy

    for flag, name, stem in (
        ("beam_only", "_beam_table", "beam"),
        ("load_torque_only", "_load_torque_table", "load_torque"),
        ("whole_chain_only", "_whole_chain_table", "whole_chain"),
    ):
        seen = []

        def table(seeds, quick, progress, stem=stem, seen=seen):
            seen.append(list(seeds))
            return f"{stem} table", {stem: 1}

        monkeypatch.setattr(accuracy, name, table)
        out = tmp_path / stem
        result = accuracy.run(out, 2, 3, False, lambda _: None, **{flag: True})
        assert seen == [[1, 2, 3]] and result["table"] == f"{stem} table"
        assert (out / f"{stem}.md").read_text() == f"{stem} table"
        assert json.loads((out / f"{stem}.json").read_text())[stem] == 1
        assert result["files"] == (f"{stem}.md", f"{stem}.json")
