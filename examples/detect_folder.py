"""Detect objects in a folder of RGB-D frames; write bop_toolkit's results CSV and overlays.

    python3 examples/detect_folder.py SCENE_DIR CAMERA_JSON OUT_DIR BANK_OR_MESH [...]

SCENE_DIR holds rgb/ and depth/ with the same file names (a BOP scene folder); a mesh (.stl,
.ply, .obj in millimetres) is trained first. Frame numbers are the files' stems.
"""
import pathlib, sys, time
import cv2, vkpose

scene, camera, out = map(pathlib.Path, sys.argv[1:4])
banks = [vkpose.Bank.load(p) if p.endswith(".vkpb") else vkpose.train(p, units="mm", camera=camera, progress=True)
         for p in sys.argv[4:]]
detector, K, rows = vkpose.Detector(banks), vkpose.Camera.load(camera), []
out.mkdir(parents=True, exist_ok=True)
for rgb_path in sorted((scene / "rgb").glob("*.png")):
    rgb = cv2.imread(str(rgb_path))
    depth = cv2.imread(str(scene / "depth" / rgb_path.name), cv2.IMREAD_UNCHANGED)
    start = time.perf_counter()
    result = detector.detect(rgb, depth, K)
    seconds = time.perf_counter() - start
    rows += [dict(scene_id=0, im_id=int(rgb_path.stem), obj_id=d.bank + 1, score=d.score, R=d.R, t=d.t, time=seconds)
             for d in result]
    cv2.imwrite(str(out / rgb_path.name), vkpose.draw(rgb, result))
    print(f"{rgb_path.name}: {len(result)} detections in {seconds:.2f} s")
vkpose.write_bop_results(out / "results.csv", rows, overwrite=True)
