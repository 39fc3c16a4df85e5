"""Fixtures of the Python tests: the shared real frames, the CLI to compare with, banks trained
once (cached in the build folder, shared with the C++ tests), and a check that no test makes
the Vulkan validation layer report an error (ctest runs them with VKPOSE_VALIDATION=1)."""

import json
import os
import pathlib
import subprocess

import pytest

import vkpose

REPO = pathlib.Path(__file__).resolve().parents[2]
SHARED = pathlib.Path(os.environ.get("VKPOSE_SHARED_DATA_DIR", REPO.parent / "shared" / "data"))


def _require(path, what):
    """Skip (or, where VKPOSE_REQUIRE_DATA is set, as in CI, fail) without the shared data."""
    if not path.exists():
        message = "%s not found (%s): the real frames live in ../shared/data" % (what, path)
        if os.environ.get("VKPOSE_REQUIRE_DATA"):
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def icbin():
    return _require(SHARED / "icbin", "IC-BIN frames")


@pytest.fixture(scope="session")
def lmo():
    return _require(SHARED / "lmo_scene2_frame3", "the LM-O frame")


@pytest.fixture(scope="session")
def cli():
    """Runs the vkpose command: (exit code, stdout, stderr)."""
    exe = os.environ.get("VKPOSE_CLI", str(REPO / "build" / "release" / "vkpose"))
    if not os.path.exists(exe):
        pytest.skip("the vkpose command is not built (%s)" % exe)

    def run(*args):
        p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        return p.returncode, p.stdout, p.stderr

    return run


@pytest.fixture(scope="session")
def cache_dir(tmp_path_factory):
    return os.environ.get("VKPOSE_TEST_CACHE_DIR") or str(tmp_path_factory.mktemp("bank-cache"))


@pytest.fixture(scope="session")
def icbin_bank(icbin, cache_dir, tmp_path_factory):
    """The coffee cup's default bank for the IC-BIN camera (what `vkpose train` makes), and its file."""
    bank = vkpose.train(SHARED / "meshes" / "coffee_cup.stl", camera=vkpose.Camera.load(icbin / "camera.json"),
                        symmetric=True, cache_dir=cache_dir)
    path = tmp_path_factory.mktemp("banks") / "coffee_cup.vkpb"
    bank.save(path)
    return bank, path


@pytest.fixture(scope="session")
def lmo_banks(lmo, cache_dir, tmp_path_factory):
    """Two LM-O objects' banks as the C++ LM-O test trains them (--radii 0.9:1.3:0.1), and their files."""
    info = json.loads((lmo / "models" / "models_info.json").read_text())
    camera = vkpose.Camera.load(lmo / "camera.json")
    folder = tmp_path_factory.mktemp("lmo-banks")
    banks, paths = [], []
    for obj_id in (5, 8):
        entry = info[str(obj_id)]
        symmetric = bool(entry.get("symmetries_discrete") or entry.get("symmetries_continuous"))
        bank = vkpose.train(lmo / "models" / ("obj_%06d.ply" % obj_id), units="mm", camera=camera,
                            radii="0.9:1.3:0.1", symmetric=symmetric, cache_dir=cache_dir)
        path = folder / ("obj_%06d.vkpb" % obj_id)
        bank.save(path)
        banks.append(bank)
        paths.append(path)
    return banks, paths


@pytest.fixture(autouse=True)
def no_validation_errors():
    before = vkpose._vkpose._validation_errors()
    yield
    assert vkpose._vkpose._validation_errors() == before, "the Vulkan validation layer reported errors"


@pytest.fixture(scope="session")
def bracket_bank():
    """A small bank of the demo's angle bracket (a few hundred templates: quick to train)."""
    return vkpose.train(REPO / "assets" / "meshes" / "angle_bracket.ply", units="mm", views=30, radii="0.6:0.8:0.1",
                        inplane="-30:30:30")


@pytest.fixture(scope="session")
def meshes():
    return _require(SHARED / "meshes", "the shared meshes")
