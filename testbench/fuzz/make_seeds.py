#!/usr/bin/env python3
"""make_seeds.py: the seed inputs the fuzz corpus (testbench/fuzz/corpus/) was grown from.

Usage: testbench/fuzz/make_seeds.py OUT_DIR [--root REPO] [--assimp-models DIR]

Writes OUT_DIR/<target>/<seed> for every target of testbench/fuzz/CMakeLists.txt, in each
target's input format (the header comment of fuzz_<target>.cpp):
  scene    the scene files of vectors/scenes and small scenes of every builtin mesh and light
  config   the registry's configuration files (vectors/config)
  prom     2 parameter bytes + the first words of each checked-in hex PROM (vectors/prom)
  vectors  the first cycles of each checked-in vector file (vectors/cycles)
  mesh     1 format byte + the small OFF, PLY and STL files of assimp-testmodels and a
           binary STL made here
  span     one input per flag of the differential target's format
Comment lines naming repository files are left out of the text seeds, so that mutated copies
in the corpus do not name files that do not exist (scripts/check_docs.py checks such names).
scripts/fuzz.sh --seed runs it and merges the seeds into the corpus.
"""
import argparse
import os
import struct

FORMAT_BYTE = {".off": 0, ".ply": 1, ".stl": 2}


def write(out, target, name, data):
    os.makedirs(os.path.join(out, target), exist_ok=True)
    with open(os.path.join(out, target, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def scene_seeds(out, root):
    scenes = os.path.join(root, "vectors", "scenes")
    for name in sorted(os.listdir(scenes)):
        if name.endswith(".json"):
            with open(os.path.join(scenes, name), "rb") as f:
                write(out, "scene", name, f.read())
    write(out, "scene", "torus_point.json",
          '{"lights": [{"type": "point", "position": [2, 2, -2]}], "objects": [{"mesh": "builtin:torus(1,0.3,8,6)",'
          ' "transform": {"scale": [1, -1, 1], "rotate_deg": [10, 20, 30]}}]}')
    write(out, "scene", "plane_camera.json",
          '{"camera": {"width": 16, "height": 9, "px_per_unit": 4, "eye": [0, 1, -2]}, "lights": [],'
          ' "materials": [{"name": "m", "colour": [0.1, 0.2, 0.3], "brdf": "cook-torrance", "roughness": 0.5,'
          ' "f0": 0.9}], "objects": [{"mesh": "builtin:plane(2,2,2)", "material": "m"}]}')
    write(out, "scene", "sphere_min.json", '{"objects": [{"name": "s", "mesh": "builtin:sphere(0.5,4)"}]}')


def config_seeds(out, root):
    configs = os.path.join(root, "vectors", "config")
    for name in sorted(os.listdir(configs)):
        with open(os.path.join(configs, name), "rb") as f:
            write(out, "config", name, f.read())


def words_of(path):
    with open(path) as f:
        return [l.strip() for l in f if l.strip() and not l.startswith("//")]


def prom_seeds(out, root):
    proms = os.path.join(root, "vectors", "prom")
    for name in sorted(os.listdir(proms)):
        if not name.endswith(".hex"):
            continue
        words = words_of(os.path.join(proms, name))[:16]
        bits = 4 * len(words[0])
        body = "// fit and format\n" + "\n".join(words) + "\n"
        write(out, "prom", name, bytes([bits - 1, len(words) - 1]) + body.encode())


def vector_seeds(out, root, cycles=24):
    vecs = os.path.join(root, "vectors", "cycles")
    for name in sorted(os.listdir(vecs)):
        with open(os.path.join(vecs, name)) as f:
            lines = f.read().split("\n")
        head = [l for l in lines if l.startswith("# ") and l.split(" ")[1] in ("unit", "config", "params", "prom", "latency")]
        data = [l for l in lines if l and not l.startswith("#")][:cycles]
        write(out, "vectors", name, "\n".join(head + data) + "\n")


def binary_stl():
    tris = [((0, 0, 1), (0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 1), (1, 0, 0), (1, 1, 0), (0, 1, 0))]
    data = b"seed".ljust(80, b" ") + struct.pack("<I", len(tris))
    for t in tris:
        data += struct.pack("<12f", *[c for v in t for c in v]) + b"\0\0"
    return data


def mesh_seeds(out, root, models, max_size=4096):
    for sub in ("OFF", "PLY", "STL"):
        d = os.path.join(models, sub)
        if not os.path.isdir(d):
            continue
        for name in sorted(os.listdir(d)):
            ext = os.path.splitext(name)[1].lower() or "." + sub.lower()  # formatDetection: no extension
            path = os.path.join(d, name)
            if ext in FORMAT_BYTE and os.path.getsize(path) <= max_size:
                with open(path, "rb") as f:
                    write(out, "mesh", f"{sub}_{name}", bytes([FORMAT_BYTE[ext]]) + f.read())
    write(out, "mesh", "two_triangles_binary.stl", bytes([FORMAT_BYTE[".stl"]]) + binary_stl())


def span_seed(flags, width, height, subpixel, triangles, widths=None, frac=None, ready=None):
    """An input of fuzz_span.cpp's format; triangles: [(shift, ashift, [(x, y, [attr...])] * 3)]."""
    b = bytes([flags, width - 1, height - 1, subpixel - 1])
    if widths:
        b += bytes(widths)
    if frac:
        b += bytes(frac)
    if ready is not None:
        b += struct.pack("<I", ready)
    for shift, ashift, verts in triangles:
        b += bytes([shift, ashift])
        for x, y, attrs in verts:
            if flags & 8:
                b += struct.pack("<dd", x, y)
            else:
                b += struct.pack("<hh", int(x * (1 << shift)), int(y * (1 << shift)))
            b += b"".join(struct.pack("<i", int(a * (1 << ashift))) for a in attrs)
    return b


def span_seeds(out):
    colour = lambda r, g, b, z: [r, g, b, z]
    tri = [(1.5, 2.25, colour(255, 0, 0, 0.5)), (30.75, 5.5, colour(0, 255, 0, 0.25)), (12.0, 27.5, colour(0, 0, 255, 0.75))]
    big = [(-20.0, -10.0, colour(10, 20, 30, 0.1)), (80.0, 5.0, colour(200, 100, 0, 0.9)), (10.0, 70.0, colour(0, 0, 0, 0.5))]
    sliver = [(0.5, 0.5, colour(1, 2, 3, 0)), (60.5, 30.5, colour(3, 2, 1, 0)), (30.5, 15.75, colour(0, 0, 0, 1))]
    seeds = {
        "one_triangle": span_seed(0, 40, 30, 4, [(4, 4, tri)]),
        "clipped_large": span_seed(0, 64, 48, 4, [(2, 4, big)]),
        "four_triangles": span_seed(3, 64, 48, 4, [(4, 4, tri), (2, 4, big), (4, 4, sliver), (4, 4, tri[::-1])]),
        # NumAttr 4, AttrBits 24, CoordBits 12, RemBits 20, PixBits 6, TagBits 8; frac bits 4, 4, 4, 12
        "own_widths": span_seed(4 | 16, 32, 32, 3, [(4, 4, tri)], widths=[3, 16, 4, 18, 5, 7], frac=[4, 4, 4, 12]),
        "raw_doubles": span_seed(8, 40, 30, 4, [(0, 4, tri)]),
        "frac_bits": span_seed(16, 40, 30, 4, [(4, 4, tri)], frac=[8, 8, 8, 20]),
        "back_pressure": span_seed(32, 40, 30, 4, [(4, 4, tri)], ready=0x5A5A3C3C),
        "subpixel8": span_seed(0, 40, 30, 8, [(7, 4, tri)]),
    }
    for name, data in seeds.items():
        write(out, "span", name, data)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--root", default=os.path.normpath(os.path.join(here, "..", "..")))
    ap.add_argument("--assimp-models", default="/usr/share/assimp/models")
    a = ap.parse_args()
    scene_seeds(a.out, a.root)
    config_seeds(a.out, a.root)
    prom_seeds(a.out, a.root)
    vector_seeds(a.out, a.root)
    mesh_seeds(a.out, a.root, a.assimp_models)
    span_seeds(a.out)


if __name__ == "__main__":
    main()
