"""Helpers of scripts/small-parts.sh (plain python3, no numpy).

  python3 small_parts.py scale SRC.ply DST.ply FACTOR
      the binary PLY's vertex positions (x, y, z: the first three floats of each vertex) times
      FACTOR, in float32 as numpy would multiply them
  python3 small_parts.py visibility OUT SEED [SEED ...]
      found instances by how much of each is visible, over the seeds' datasets OUT/binSEED and
      their results OUT/vkpose_binSEED-results.csv (ADD below 0.15 of the diameter, each estimate
      best score first to the nearest free instance, as `vkpose eval` counts)
"""
import csv
import json
import math
import struct
import sys

SIZES = {"float": 4, "uchar": 1, "int": 4, "uint": 4}


def vertex_layout(data):
    """(end of the header, vertex count, bytes a vertex) of a binary little-endian PLY whose
    vertices start with x, y, z floats."""
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert "format binary_little_endian 1.0" in header, "binary little-endian PLY expected"
    count = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    props, in_vertex = [], False
    for l in header:
        if l.startswith("element"):
            in_vertex = l.startswith("element vertex")
        elif l.startswith("property") and in_vertex:
            props.append(l.split()[1])
    assert props[:3] == ["float"] * 3, "x, y, z floats first"
    return end, count, sum(SIZES[p] for p in props)


def scale(src, dst, factor):
    factor = struct.unpack("<f", struct.pack("<f", float(factor)))[0]  # float32 products, as numpy's
    data = open(src, "rb").read()
    end, count, stride = vertex_layout(data)
    body = bytearray(data[end:])
    for i in range(count):
        xyz = struct.unpack_from("<3f", body, i * stride)
        struct.pack_into("<3f", body, i * stride, *(factor * c for c in xyz))
    open(dst, "wb").write(data[:end] + bytes(body))


def vertices(path):
    data = open(path, "rb").read()
    end, count, stride = vertex_layout(data)
    return [struct.unpack_from("<3f", data, end + i * stride) for i in range(count)]


def placed(R, t, v):
    return [sum(R[3 * r + c] * v[c] for c in range(3)) + t[r] for r in range(3)]


def visibility(out, seeds):
    buckets = [(0.0, 0.4, "under 40 %"), (0.4, 0.6, "40-60 %"), (0.6, 0.8, "60-80 %"), (0.8, 1.01, "80 % and more")]
    found, total = [0] * len(buckets), [0] * len(buckets)
    for seed in seeds:
        ds = f"{out}/bin{seed}"
        scene = f"{ds}/test/000001"
        gt, info = json.load(open(f"{scene}/scene_gt.json")), json.load(open(f"{scene}/scene_gt_info.json"))
        diameter = json.load(open(f"{ds}/models/models_info.json"))["1"]["diameter"]
        model = vertices(f"{ds}/models/obj_000001.ply")
        estimates = {}
        for r in csv.DictReader(open(f"{out}/vkpose_bin{seed}-results.csv")):
            estimates.setdefault(r["im_id"], []).append(
                (float(r["score"]), [float(x) for x in r["R"].split()], [float(x) for x in r["t"].split()]))
        for im, instances in gt.items():
            truth = [[placed(g["cam_R_m2c"], g["cam_t_m2c"], v) for v in model] for g in instances]
            taken = set()
            for _, R, t in sorted(estimates.get(im, []), key=lambda e: -e[0]):
                seen = [placed(R, t, v) for v in model]
                best = None
                for k, points in enumerate(truth):
                    if k in taken:
                        continue
                    error = sum(math.dist(a, b) for a, b in zip(seen, points)) / len(model)
                    if error < 0.15 * diameter and (best is None or error < best[0]):
                        best = (error, k)
                if best:
                    taken.add(best[1])
            for k in range(len(instances)):
                v = info[im][k]["visib_fract"]
                b = next(i for i, (lo, hi, _) in enumerate(buckets) if lo <= v < hi)
                total[b] += 1
                found[b] += k in taken
    print("found by visibility, seeds " + " ".join(seeds) + ":")
    for (_, _, name), f, n in zip(buckets, found, total):
        print(f"  {name:>14}: {f} of {n}")


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "scale":
        scale(*sys.argv[2:])
    elif len(sys.argv) >= 4 and sys.argv[1] == "visibility":
        visibility(sys.argv[2], sys.argv[3:])
    else:
        sys.exit(__doc__)
