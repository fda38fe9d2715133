# Fixtures of the Python module's tests: the module built by CMake (PYTHONPATH=<build>/python), the
# `pointrast` CLI of the same build tree (POINTRAST_CLI names another), and the shared test data
# (POINTRAST_DATA, else ../shared/data beside the checkout, as the C++ tests read it).
import os
import pathlib
import subprocess

import numpy as np
import pytest

import pointrast

from pngread import read_png

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def data():
    path = pathlib.Path(os.environ.get("POINTRAST_DATA", ROOT.parent / "shared" / "data"))
    assert path.is_dir(), "test data not found at %s (set POINTRAST_DATA)" % path
    return path


@pytest.fixture(scope="session")
def cli_path():
    given = os.environ.get("POINTRAST_CLI")
    if given:
        path = pathlib.Path(given)
    else:  # the build tree the module comes from: <build>/python/pointrast/__init__.py -> <build>/pointrast
        path = pathlib.Path(pointrast.__file__).resolve().parents[2] / "pointrast"
    assert path.is_file(), "the pointrast CLI was not found at %s (set POINTRAST_CLI)" % path
    return path


@pytest.fixture
def cli(cli_path, tmp_path):
    """Runs `pointrast render ARGS -o OUT.png` and returns the image as (H, W, 3) uint8."""

    def render(*args):
        out = tmp_path / "cli.png"
        if out.exists():
            out.unlink()
        run = subprocess.run([str(cli_path), "render", *map(str, args), "-o", str(out), "--quiet", "--frames", "1"],
                             capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        return read_png(out)

    return render


def rgb(image):
    """The RGB channels of a render() image, as the CLI's PNG holds them."""
    return np.ascontiguousarray(image[..., :3])
