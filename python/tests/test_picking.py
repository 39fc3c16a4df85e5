"""Bin picking from Python (vkpose.plan_picks) on the real IC-BIN frame (cups piled in a bin): the
cup's suction grasp on its side, copied about the cup's axis, is offered for every detected cup, and equals `vkpose detect
--grasps`' JSON; a grasp file of an object the detector has no bank for is a ValueError."""

import json

import cv2
import pytest

import vkpose

CUP_GRASPS = {
    "object": "coffee_cup",
    "gripper": {"shape": "cylinder", "radius_mm": 15, "length_mm": 120},
    "grasps": [
        {"name": "side", "priority": 2, "position_mm": [45, 0, 0], "approach": [-1, 0, 0], "suction_radius_mm": 10},
        {"name": "top", "priority": 1, "position_mm": [0, 0, 60], "approach": [0, 0, -1], "suction_radius_mm": 10},
        {"name": "bottom", "position_mm": [0, 0, -60], "approach": [0, 0, 1], "suction_radius_mm": 10},
    ],
}


def test_a_cups_grasp_is_offered_for_every_detected_cup(icbin, icbin_bank, cli, tmp_path):
    bank, bank_path = icbin_bank
    grasps = tmp_path / "cup.grasps.json"
    grasps.write_text(json.dumps(CUP_GRASPS))
    rgb_path, depth_path = icbin / "scene2" / "rgb" / "0000.png", icbin / "scene2" / "depth" / "0000.png"
    camera = vkpose.Camera.load(icbin / "camera.json")
    depth = cv2.imread(str(depth_path), cv2.IMREAD_UNCHANGED)
    result = vkpose.Detector([bank]).detect(cv2.imread(str(rgb_path)), depth, camera.K)
    assert len(result) >= 3
    plan = vkpose.plan_picks(result, grasps, depth, max_tilt=90)
    assert len(plan["grasps"]) == len(result)
    for i, g in enumerate(plan["grasps"]):
        assert g["valid"], "cup %d: no grasp offered (%s)" % (i, g["refused"])
    assert sorted(p["detection"] for p in plan["picks"]) == list(range(len(result)))
    first = plan["picks"][0]["grasp"]
    assert len(first["R"]) == 9 and first["tilt_deg"] <= 90 and first["suction_radius_m"] == pytest.approx(0.01)

    code, _, err = cli("-q", "detect", "--bank", bank_path, "--rgb", rgb_path, "--depth", depth_path, "--camera",
                       icbin / "camera.json", "--grasps", grasps, "--max-tilt", 90, "--out", tmp_path / "d.json")
    assert code == 0, err
    doc = json.loads((tmp_path / "d.json").read_text())
    assert [p["detection"] for p in doc["picks"]] == [p["detection"] for p in plan["picks"]]
    assert [d["grasps"]["valid"][0]["name"] for d in doc["detections"]] == [g["valid"][0]["name"] for g in plan["grasps"]]

    other = tmp_path / "mug.grasps.json"
    other.write_text(json.dumps(dict(CUP_GRASPS, object="mug")))
    with pytest.raises(ValueError, match="no bank is for"):
        vkpose.plan_picks(result, other, depth)
    for share in ("min_outline_on_edges", "min_colour_agreement", "colour_outline_allowance"):
        with pytest.raises(ValueError, match=share + r" must be in \[0, 1\]"):
            vkpose.plan_picks(result, grasps, depth, **{share: 1.5})
