"""Detection from numpy arrays: the same poses as `vkpose detect` on the real IC-BIN and LM-O
frames, bad arrays as clear errors, the GIL released while it works, and one detector used
from two threads."""

import json
import threading
from concurrent.futures import ThreadPoolExecutor

import cv2
import numpy as np
import pytest

import vkpose


def cli_detections(cli, tmp_path, banks, rgb, depth, camera, *extra):
    out = tmp_path / "det.json"
    args = ["-q", "detect", "--rgb", rgb, "--depth", depth, "--camera", camera, "--out", out, *extra]
    for b in banks:
        args += ["--bank", b]
    code, _, err = cli(*args)
    assert code == 0, err
    return json.loads(out.read_text())


def assert_same_detections(result, doc):
    """Python's detections equal the CLI's JSON (which rounds R and t to 6 decimals, scores to 4)."""
    assert len(result.detections) == len(doc["detections"])
    assert len(result.rejected) == len(doc["rejected"])
    for d, j in zip(result.detections, doc["detections"]):
        assert d.object == j["object"]
        assert d.score == pytest.approx(j["score"], abs=1e-4)
        np.testing.assert_allclose(d.R, np.reshape(j["R"], (3, 3)), atol=2e-6)
        np.testing.assert_allclose(d.t, j["t"], atol=2e-6)
        np.testing.assert_allclose(d.bbox, j["bbox"], atol=0.06)
        assert d.templates == j["templates"] and d.verified == j["verified"]
    # The whole document, but for the paths the CLI names and the timings.
    mine = json.loads(result.to_json())
    for key in ("rgb", "depth", "timings_ms"):
        mine.pop(key), doc.pop(key)
    assert mine == doc


def test_icbin_frame_equals_the_cli(icbin, icbin_bank, cli, tmp_path):
    bank, bank_path = icbin_bank
    assert bank.object == "coffee_cup" and bank.templates == 14040 and bank.up_axis == "+z"
    rgb_path, depth_path = icbin / "scene2" / "rgb" / "0000.png", icbin / "scene2" / "depth" / "0000.png"
    camera = vkpose.Camera.load(icbin / "camera.json")
    rgb = cv2.imread(str(rgb_path))
    depth = cv2.imread(str(depth_path), cv2.IMREAD_UNCHANGED)
    result = vkpose.Detector([bank]).detect(rgb, depth, camera.K)
    assert len(result) >= 3, result
    assert_same_detections(result, cli_detections(cli, tmp_path, [bank_path], rgb_path, depth_path,
                                                  icbin / "camera.json"))
    # What the module reads equals what cv2 reads.
    bgr, depth_mm = vkpose.load_frame(rgb_path, depth_path)
    assert np.array_equal(bgr, rgb) and np.array_equal(depth_mm, depth)


def test_lmo_frame_equals_the_cli_with_depth_in_metres(lmo, lmo_banks, cli, tmp_path):
    banks, paths = lmo_banks
    scene = lmo / "test" / "000002"
    rgb_path, depth_path = scene / "rgb" / "000003.png", scene / "depth" / "000003.png"
    camera = vkpose.load_scene_cameras(scene / "scene_camera.json")[3]
    rgb = cv2.imread(str(rgb_path))
    depth_m = cv2.imread(str(depth_path), cv2.IMREAD_UNCHANGED).astype(np.float32) * (camera.depth_scale / 1000.0)
    # Bank files and bank objects, RGB order with the flag: the same detector.
    detector = vkpose.Detector([str(p) for p in paths])
    result = detector.detect(np.ascontiguousarray(rgb[:, :, ::-1]), depth_m, camera.K, color="rgb")
    assert len(result) >= 1, result
    doc = cli_detections(cli, tmp_path, paths, rgb_path, depth_path, scene / "scene_camera.json",
                         "--camera-entry", "3")
    assert_same_detections(result, doc)
    for d in result:
        assert d.R.shape == (3, 3) and d.t.shape == (3,) and d.pose.shape == (4, 4)
        np.testing.assert_allclose(d.R @ d.R.T, np.eye(3), atol=1e-4)
        assert 0.5 < d.t[2] < 2.0  # metres
        assert d.to_dict()["object"] == d.object
    assert set(result.timings_ms) >= {"features", "similarity"}


def test_bad_arrays_are_clear_errors(bracket_bank):
    det = vkpose.Detector([bracket_bank])
    rgb = np.zeros((480, 640, 3), np.uint8)
    depth = np.full((480, 640), 700, np.uint16)
    K = vkpose.Camera.load(__import__("conftest").REPO / "assets" / "camera_primesense.json").K
    cases = [
        (dict(rgb=rgb.astype(np.float32)), "uint8"),
        (dict(rgb=rgb[:, :, 0]), "HxWx3"),
        (dict(rgb=rgb[:, :, ::-1]), "C-contiguous"),
        (dict(rgb=np.zeros((0, 640, 3), np.uint8)), "empty"),
        (dict(rgb="image.png"), "numpy array|HxWx3"),
        (dict(depth=np.ascontiguousarray(depth[:, :320])), "same size"),
        (dict(depth=depth.T), "C-contiguous|same size"),
        (dict(depth=depth.astype(np.int32)), "uint16 millimetres or float32 metres"),
        (dict(depth=np.zeros((480, 640, 1), np.uint16)), "HxW depth"),
        (dict(depth=np.zeros_like(depth)), "all zero"),
        (dict(K=np.eye(4)), "3x3"),
        (dict(K=[[500, 0, 320], [0, 500, 240]]), "3x3"),
        (dict(K=np.array([[-500, 0, 320], [0, 500, 240], [0, 0, 1]])), "focal"),
        (dict(K=np.array([[500, 0, 320], [0, 500, 240], [0, 0, 2]])), "intrinsic matrix"),
        (dict(K=np.array([[500, 0, 5000], [0, 500, 240], [0, 0, 1.0]])), "principal point"),
    ]
    for change, message in cases:
        args = dict(rgb=rgb, depth=depth, K=K)
        args.update(change)
        with pytest.raises(ValueError, match=message):
            det.detect(args["rgb"], args["depth"], args["K"])
    with pytest.raises(ValueError, match="color"):
        det.detect(rgb, depth, K, color="hsv")
    with pytest.raises(ValueError, match="depth_scale"):
        det.detect(rgb, depth, K, depth_scale=-1)
    # Still usable after all that.
    assert len(det.detect(rgb, depth, K).detections) == 0


def test_colour_only_with_depth_none(icbin, icbin_bank):
    bank, _ = icbin_bank
    rgb = cv2.imread(str(icbin / "scene2" / "rgb" / "0000.png"))
    det = vkpose.Detector([bank])
    result = det.detect(rgb, None, vkpose.Camera.load(icbin / "camera.json"))
    assert set(result.timings_ms) >= {"features", "similarity", "edges", "contour_fit", "verification"}
    assert result.matches > 0
    for d in list(result.detections) + list(result.rejected):
        assert d.colour_only and d.to_dict()["colour_only"]
        assert 0.0 <= d.explained_edges <= 1.0
        # Measured only for a mesh without colours over a surface of one colour.
        assert d.plain_outline_edges is None or 0.0 <= d.plain_outline_edges <= 1.0
        assert ("plain_outline_edges" in d.to_dict()) == (d.plain_outline_edges is not None)
        # Measured at every pose that was scored; the score holds a power of it.
        assert d.region_contrast is None or -1.0 <= d.region_contrast <= 1.0
        assert ("region_contrast" in d.to_dict()) == (d.region_contrast is not None)
    for d in result.detections:
        assert d.region_contrast is not None
    doc = json.loads(result.to_json())
    assert doc["depth"] == ""
    assert all(d["colour_only"] for d in doc["detections"])


def synthetic_frame(bank_mesh, seed):
    return vkpose.synth_frame(bank_mesh, seed=seed, instances=2, clutter=2, units="mm")


def test_the_gil_is_released_and_threads_take_turns(bracket_bank):
    mesh = __import__("conftest").REPO / "assets" / "meshes" / "angle_bracket.ply"
    frame = synthetic_frame(mesh, seed=3)
    assert frame["rgb"].shape == (480, 640, 3) and frame["depth"].dtype == np.uint16 and frame["gt"]
    det = vkpose.Detector([bracket_bank])
    args = (frame["rgb"], frame["depth"], frame["camera"])
    reference = det.detect(*args).to_json()

    # While one thread detects, this one keeps running Python.
    done = threading.Event()
    ticks = 0

    def work():
        det.detect(*args)
        done.set()

    worker = threading.Thread(target=work)
    worker.start()
    while not done.is_set():
        ticks += 1
    worker.join()
    assert ticks > 1000, "the main thread stood still while detect() ran: the GIL was held"

    # Two threads on one detector: calls take turns and give the same answer.
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(lambda _: det.detect(*args).to_json(), range(4)))

    def without_timings(text):
        doc = json.loads(text)
        doc.pop("timings_ms")
        return doc

    assert all(without_timings(r) == without_timings(reference) for r in results)


def test_draw(icbin, icbin_bank):
    bank, _ = icbin_bank
    rgb, depth = vkpose.load_frame(icbin / "scene2" / "rgb" / "0000.png", icbin / "scene2" / "depth" / "0000.png")
    det = vkpose.Detector([bank], config={"detector": {"estimate_poses": False}})
    result = det.detect(rgb, depth, vkpose.Camera.load(icbin / "camera.json"))
    assert len(result) >= 3
    overlay = vkpose.draw(rgb, result)
    assert overlay.shape == rgb.shape and overlay.dtype == np.uint8
    assert not np.array_equal(overlay, rgb)
    one = vkpose.draw(rgb, result.detections[:1], legend=False)
    assert not np.array_equal(one, rgb) and not np.array_equal(one, overlay)
    side = vkpose.draw(rgb, result, depth=depth)
    assert side.shape == (480, 1280, 3)
    as_rgb = vkpose.draw(np.ascontiguousarray(rgb[:, :, ::-1]), result, color="rgb")
    assert np.array_equal(as_rgb[:, :, ::-1], overlay)
    assert np.array_equal(vkpose.draw(rgb, []), rgb)
    with pytest.raises(ValueError, match="frame"):
        vkpose.draw(rgb[:240].copy(), result)
