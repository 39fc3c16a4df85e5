"""Helpers of scripts/small-parts.sh (plain python3, no numpy).

  python3 small_parts.py scale SRC.ply DST.ply FACTOR
      the binary PLY's vertex positions (x, y, z: the first three floats of each vertex) times
      FACTOR, in float32 as numpy would multiply them
  python3 small_parts.py visibility OUT SEED [SEED ...]
      found instances by how much of each is visible, per method, summed over the seeds'
      `vkpose eval` reports OUT/binSEED-report.json (their "by_visibility" bins)
"""
import json
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


def visibility(out, seeds):
    """Sums `vkpose eval`'s found-by-visibility bins (its --report) over the seeds, per method."""
    methods = {}
    for seed in seeds:
        report = json.load(open(f"{out}/bin{seed}-report.json"))
        for name, method in report["methods"].items():
            total = methods.setdefault(name, [])
            for b, bin_ in enumerate(method["by_visibility"]):
                if b == len(total):
                    total.append([bin_["visib_fract"], 0, 0])
                total[b][1] += bin_["found"]
                total[b][2] += bin_["instances"]
    print("found by visibility, seeds " + " ".join(seeds) + ":")
    for name, bins in methods.items():
        print(f"  {name}: " + ", ".join(f"{lo * 100:.0f}-{hi * 100:.0f} %: {f} of {n}" for (lo, hi), f, n in bins))


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "scale":
        scale(*sys.argv[2:])
    elif len(sys.argv) >= 4 and sys.argv[1] == "visibility":
        visibility(sys.argv[2], sys.argv[3:])
    else:
        sys.exit(__doc__)
