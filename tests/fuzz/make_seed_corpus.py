#!/usr/bin/python3
"""Writes small seed corpora for the libFuzzer targets (tests/fuzz/fuzz_*.cpp).

Usage: make_seed_corpus.py OUT_DIR   ->  OUT_DIR/pickle, OUT_DIR/npz, OUT_DIR/load_model

Seeds are tiny valid model files in every supported flavour (Python-2 protocol-2 pickles written
opcode by opcode, protocol 3-5 pickles, .npz stored / deflated / Fortran order / big-endian, .npy)
built with the fixture code of tests/smpl/fixtures/make_io_fixtures.py. Nothing is committed.
"""
import io
import os
import pickle
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


def main():
    out = sys.argv[1]
    dirs = {k: os.path.join(out, k) for k in ("pickle", "npz", "load_model")}
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


if __name__ == "__main__":
    main()
