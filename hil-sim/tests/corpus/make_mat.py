"""Writes the small MAT-files in this folder (run once; the tests read the committed files).

    python3 make_mat.py    # needs numpy and scipy
"""
import numpy as np
from scipy.io import savemat

n = 50
t = np.arange(n) / 1000.0
b = 0.5 * np.sin(2 * np.pi * 20 * t)
torque = 2.0 * b + 0.1 * np.cos(2 * np.pi * 20 * t)
good = {
    "t": t.reshape(-1, 1),  # column vector
    "b": b.reshape(-1, 1),
    "torque": torque.reshape(1, -1),  # a row vector is read as well
    "speed": np.linspace(0, 10, n, dtype=np.float32).reshape(-1, 1),  # single
    "temperature": np.arange(20, 20 + n, dtype=np.int32).reshape(-1, 1),  # int32
    "fs": 1000.0,  # scalar: a constant
}
savemat("good.mat", good, do_compression=False)
savemat("good_compressed.mat", good, do_compression=True)

raw = open("good.mat", "rb").read()
open("truncated.mat", "wb").write(raw[: len(raw) * 2 // 3])

bad = dict(good)
bad["torque"] = np.arange(12.0).reshape(3, 4)
savemat("matrix_shape.mat", bad, do_compression=True)

bad = dict(good)
bad["torque"] = torque[:40].reshape(-1, 1)
savemat("length_mismatch.mat", bad)

bad = dict(good)
f = torque.copy()
f[16] = np.nan  # sample 17
bad["torque"] = f.reshape(-1, 1)
savemat("nan.mat", bad)

bad = dict(good)
tt = t.copy()
tt[30] = tt[29]  # sample 31 repeats sample 30's time
bad["t"] = tt.reshape(-1, 1)
savemat("time_not_increasing.mat", bad)

bad = dict(good)
bad["notes"] = "bench 2, coil A"
savemat("char_variable.mat", bad)

# Not a recording at all: 700 random bytes.
import random

random.seed(7)
open("garbage.bin", "wb").write(bytes(random.randrange(256) for _ in range(700)))
