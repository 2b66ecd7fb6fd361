#!/usr/bin/python3
"""Writes small seed corpora for the libFuzzer targets (tests/fuzz/fuzz_*.cpp).

Usage: make_seed_corpus.py OUT_DIR   ->  OUT_DIR/<reader> for every fuzz_<reader> target

Seeds are tiny valid files in every supported flavour: model files (Python-2 protocol-2 pickles
written opcode by opcode, protocol 3-5 pickles, .npz stored / deflated / Fortran order /
big-endian, .npy) built with the fixture code of tests/smpl/fixtures/make_io_fixtures.py; a
skinned glTF triangle (.gltf with a data: URI, and .glb); OBJ and PLY (ascii, binary) meshes;
JSON; the first lines of the sample pose logs; a session journal; the shipped protocol files;
CSV with quoting. Nothing is committed.
"""
import base64
import io
import json
import os
import pickle
import struct
import sys

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "smpl", "fixtures"))
import make_io_fixtures as fx  # noqa: E402


def npz_bytes(arrays, compressed=False):
    buf = io.BytesIO()
    (np.savez_compressed if compressed else np.savez)(buf, **arrays)
    return buf.getvalue()


REPO = os.path.normpath(os.path.join(HERE, "..", ".."))


def gltf_seed():
    """A skinned triangle: (JSON with an embedded buffer, GLB bytes)."""
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    joints = bytes(12)
    weights = struct.pack("<12f", 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0)
    idx = struct.pack("<3I", 0, 1, 2)
    binary = pos + joints + weights + idx
    views = []
    at = 0
    for part in (pos, joints, weights, idx):
        views.append({"buffer": 0, "byteOffset": at, "byteLength": len(part)})
        at += len(part)
    doc = {
        "asset": {"version": "2.0", "extras": {"height_m": "1.70"}},
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5121, "count": 3, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5125, "count": 3, "type": "SCALAR"},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2},
                                    "indices": 3, "targets": [{"POSITION": 0}]}]}],
        "skins": [{"joints": [1, 2]}],
        "nodes": [{"mesh": 0, "skin": 0}, {"name": "root", "translation": [0, 1, 0],
                                           "children": [2]},
                  {"name": "child", "rotation": [0, 0, 0, 1], "scale": [1, 1, 1]}],
        "scenes": [{"nodes": [0, 1]}],
        "scene": 0,
    }
    glb_json = json.dumps(doc, separators=(",", ":")).encode()
    glb_json += b" " * (-len(glb_json) % 4)
    glb = (struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(glb_json) + 8 + len(binary)) +
           struct.pack("<I4s", len(glb_json), b"JSON") + glb_json +
           struct.pack("<I4s", len(binary), b"BIN\0") + binary)
    doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64," +
                                base64.b64encode(binary).decode())
    return json.dumps(doc).encode(), glb


def head_lines(path, n):
    with open(path, "rb") as fh:
        return b"".join(fh.readline() for _ in range(n))


def main():
    out = sys.argv[1]
    dirs = {k: os.path.join(out, k) for k in ("pickle", "npz", "load_model", "gltf", "obj", "ply",
                                              "json", "pose_log", "journal", "protocol", "csv")}
    for d in dirs.values():
        os.makedirs(d, exist_ok=True)

    def seed(kind, name, data):
        with open(os.path.join(dirs[kind], name), "wb") as fh:
            fh.write(data)

    m = fx.random_model(11, V=4, F=2, K=3, B=2)
    pickles = {
        "py2.pkl": fx.py2_smpl_pickle(m),
        "py2_numpy2_csr.pkl": fx.py2_smpl_pickle(m, "numpy._core.multiarray", "scipy.sparse._csc",
                                                 fmt="csr", fortran_keys=("weights",)),
        "p3.pkl": fx.py3_pickle(m, 3),
        "p4.pkl": fx.py3_pickle(m, 4, fortran_keys=("posedirs",)),
        "p5.pkl": fx.py3_pickle(m, 5, fortran_keys=("weights",)),
        "scalars_p2.pkl": pickle.dumps({"a": 1, "b": 2.5, "c": [1, (2, 3)], "d": None,
                                        "e": {"x": b"y"}, "f": True, "g": 2 ** 40}, protocol=2),
        "set_p4.pkl": pickle.dumps({"s": {1, 2}, "fs": frozenset([3])}, protocol=4),
    }
    arrays = fx.npz_arrays(m)
    mixed = dict(arrays, v_template=arrays["v_template"].astype(">f8"),
                 f=arrays["f"].astype(np.int64), shapedirs=arrays["shapedirs"].astype(np.float32),
                 joint_names=np.array(["a", "b", "c"]), meta_name=np.array("seed"))
    fortran = {k: (np.asfortranarray(v) if np.ndim(v) >= 2 else v) for k, v in arrays.items()}
    npzs = {
        "stored.npz": npz_bytes(arrays),
        "deflated.npz": npz_bytes(arrays, compressed=True),
        "fortran.npz": npz_bytes(fortran),
        "mixed.npz": npz_bytes(mixed, compressed=True),
    }
    for name, data in pickles.items():
        seed("pickle", name, data)
        seed("load_model", name, data)
    for name, data in npzs.items():
        seed("npz", name, data)
        seed("load_model", name, data)
    buf = io.BytesIO()
    np.save(buf, np.asfortranarray(np.arange(12, dtype=">i4").reshape(3, 4)))
    seed("npz", "array.npy", buf.getvalue())
    buf = io.BytesIO()
    np.save(buf, np.array(["pelvis", "hip"]))
    seed("npz", "text.npy", buf.getvalue())

    gltf, glb = gltf_seed()
    seed("gltf", "triangle.gltf", gltf)
    seed("gltf", "triangle.glb", glb)
    seed("obj", "quad.obj", b"# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n"
                            b"f 1//1 2//1 3//1 4//1\nf -1 -2 -3\n")
    ply_head = (b"ply\nformat %s 1.0\ncomment seed\nelement vertex 3\nproperty float x\n"
                b"property float y\nproperty float z\nelement face 1\n"
                b"property list uchar int vertex_indices\nend_header\n")
    seed("ply", "ascii.ply", ply_head % b"ascii" + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    seed("ply", "binary.ply", ply_head % b"binary_little_endian" +
         struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2))
    seed("json", "values.json", json.dumps({"a": [1, -2.5e-3, True, False, None],
                                            "s": "t\u00e9xt \" \\ \n", "o": {"k": {}}},
                                           ensure_ascii=True).encode())
    seed("json", "protocol.json", open(os.path.join(REPO, "assets/protocol/virtual-caliper.json"),
                                       "rb").read())
    for name in ("self-female.jsonl", "operator-male.jsonl"):
        seed("pose_log", name, head_lines(os.path.join(REPO, "assets/logs", name), 40))
    journal = [{"format": "caliper-session-journal", "version": 1,
                "protocol": "virtual-caliper", "role": "self"},
               {"type": "floor", "index": 0, "points": [[0.1, 0.0, 0.2]], "time": 1.5},
               {"type": "sample", "step": "height", "index": 0, "points": [[0, 1.7, 0]],
                "value": 1.7, "time": 3.0},
               {"type": "typed", "step": "weight", "value": 62.0, "time": 4.0},
               {"type": "typed", "step": "note", "text": "retake", "time": 5.0}]
    seed("journal", "session.journal",
         b"".join(json.dumps(r, separators=(",", ":")).encode() + b"\n" for r in journal))
    for name in ("virtual-caliper.json", "controllers.json"):
        seed("protocol", name, open(os.path.join(REPO, "assets/protocol", name), "rb").read())
    # fuzz_csv: the first byte picks the options (bit 0 per-row errors, bit 1 comment lines).
    seed("csv", "people.csv", b"\x00id,sex,height_cm,weight_kg,\"note, quoted\"\r\n"
                              b"a,female,168,62,\"say \"\"hi\"\"\"\r\nb,male,181,84,\"two\nlines\"\r\n")
    seed("csv", "people_bad_rows.csv", b"\x01id,height_cm,weight_kg\na,170,62\nb,\"171,63\n"
                                       b"c\"x,172\nd,173,65,1\ne,174,\"66")
    seed("csv", "ansur_stats.csv",
         b"\x02" + head_lines(os.path.join(REPO, "assets/models/ansur_stats.csv"), 8))


if __name__ == "__main__":
    main()
