"""Shared helpers of the Python package's tests: the `pinfeed` command to compare against.

The command is $PINFEED_BIN, else the workspace's target/release/pinfeed (built by
`cargo build --release` or `cargo test --release`); a test that needs it fails when it is missing.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]


def _binary() -> Path:
    given = os.environ.get("PINFEED_BIN")
    return Path(given) if given else ROOT / "target" / "release" / "pinfeed"


class Cli:
    """Runs the `pinfeed` command in a scratch folder."""

    def __init__(self, folder: Path):
        self.bin = _binary()
        self.folder = folder
        if not self.bin.is_file():
            pytest.fail(f"{self.bin} is missing: run `cargo build --release` (or set PINFEED_BIN)")

    def run(self, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            [str(self.bin), *args],
            cwd=self.folder,
            capture_output=True,
            text=True,
            timeout=600,
        )

    def json(self, *args: str) -> dict:
        p = self.run(*args)
        # `plan` exits 3 for a design the line does not confirm, with its JSON printed.
        assert p.returncode in (0, 3), p.stderr
        return json.loads(p.stdout)

    def error(self, *args: str) -> str:
        """The message of a command that fails: its standard error without `error: `."""
        p = self.run(*args)
        assert p.returncode == 1, (p.returncode, p.stdout)
        lines = p.stderr.strip()
        assert lines.startswith("error: "), lines
        return lines[len("error: ") :]


@pytest.fixture
def cli(tmp_path: Path) -> Cli:
    return Cli(tmp_path)


@pytest.fixture
def root() -> Path:
    return ROOT
