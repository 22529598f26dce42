"""Fixtures of the foldsynth package tests: the repository, the CLI, the gripper model."""

import os
import pathlib
import shutil

import pytest

import foldsynth

ROOT = pathlib.Path(__file__).resolve().parents[2]
GRAPH = "2, 3, (4, 8), 4, (7, 8)"


def cli_path():
    """The foldsynth binary: $FOLDSYNTH_BIN, else target/release/foldsynth (under
    $CARGO_TARGET_DIR when set), else one on PATH."""
    if os.environ.get("FOLDSYNTH_BIN"):
        return pathlib.Path(os.environ["FOLDSYNTH_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    built = target / "release" / "foldsynth"
    if built.exists():
        return built
    found = shutil.which("foldsynth")
    return pathlib.Path(found) if found else None


@pytest.fixture(scope="session")
def cli():
    path = cli_path()
    if path is None or not path.exists():
        message = "no foldsynth binary: run `cargo build --release` or set FOLDSYNTH_BIN"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def task():
    return foldsynth.Task.load(str(ROOT / "grammar" / "gripper.toml"))


@pytest.fixture(scope="session")
def model(task):
    return task.model(GRAPH, candidate=1)
