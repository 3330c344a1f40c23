"""The ``arcosim`` command run in the test's own process, for the CLI tests."""

from __future__ import annotations

from arcosim.cli import main


def run(capsys, *argv: object) -> tuple[int, str, str]:
    """``arcosim ARGV`` in this process: (exit status, stdout, stderr)."""
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err
