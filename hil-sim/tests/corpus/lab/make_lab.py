"""Writes the lab-layout corpus in this folder (run once; the tests read the committed files).

    python3 make_lab.py    # needs numpy and scipy (scipy.io.savemat, independent of hil-sim's reader)

Every file holds the same recording as `twin.csv` (a plain CSV) in another layout a lab
saves: MATLAB matrix variables, scalars, mixed lengths, a dSPACE ControlDesk struct, int16
channels, NaN and text in unused variables, compressed and plain; tab-, space- and
semicolon-separated text with decimal commas, CRLF line ends, no header. The `err_*` files
are broken on purpose at a known line or variable. Values are rounded to 8 significant
digits first so that every text layout writes them exactly.
"""
import numpy as np
from scipy.io import savemat

n = 100
fs = 100.0
t = np.arange(n) / fs
x = 1.5 * np.sin(2 * np.pi * 1.3 * t) + 0.2 * np.sin(2 * np.pi * 7.1 * t)
F = 40.0 * np.tanh(3.0 * np.gradient(x, t) / 10.0) + 5.0 * x
aux = 20.0 + 0.01 * np.arange(n)
n16 = np.round(1000 * np.sin(2 * np.pi * 0.5 * t)).astype(np.int16)
V = 2.178


def r(v):
    return [float("%.7e" % a) for a in v]


t, x, F, aux = (np.array(r(v)) for v in (t, x, F, aux))
repr = lambda v: "%r" % float(v)  # noqa: E731  (shortest text that reads back exactly)

# The clean twin: t, x, F, aux, n16 (and the constant V given with --set V=2.178).
with open("twin.csv", "w", newline="") as f:
    f.write("t,x,F,aux,n16\n")
    for i in range(n):
        f.write("%s,%s,%s,%s,%d\n" % (repr(t[i]), repr(x[i]), repr(F[i]), repr(aux[i]), n16[i]))

col = lambda v: np.asarray(v).reshape(-1, 1)

# MATLAB matrix variables as the damper lab saved them: time `Tout`, a 100×3 matrix `x_F`
# (x, F, aux), the voltage as a scalar `V`, a shorter `tout`, a NaN-holding `theta_a`, text.
theta = np.full(n, 0.5)
theta[3] = np.nan
matrix = {
    "Tout": col(t),
    "x_F": np.column_stack([x, F, aux]),
    "V": V,
    "tout": col(t[:70]),
    "theta_a": col(theta),
    "notes": "bench A, 2.178 V",
    "n16": col(n16),
}
savemat("matrix.mat", matrix, do_compression=True)
savemat("matrix_plain.mat", matrix, do_compression=False)

# One variable per channel, int16 and single storage, uncompressed.
savemat(
    "vectors_int16.mat",
    {"t": col(t), "x": col(x), "F": col(F), "aux": col(aux), "n16": col(n16), "V": V},
    do_compression=False,
)

# dSPACE ControlDesk: a struct with X (time, itself a struct with Name/Data) and Y(k).Name/.Data.
Y = np.zeros((1, 4), dtype=[("Name", object), ("Data", object), ("Unit", object)])
for k, (name, data) in enumerate(
    [('Model Root/Plant/"x"', x), ('Model Root/Plant/"F"', F), ("Model Root/aux", aux), ("n16", n16)]
):
    Y[0, k] = (name, np.asarray(data).reshape(1, -1), "-")
X = np.zeros((1, 1), dtype=[("Name", object), ("Data", object)])
X[0, 0] = ("Time", t.reshape(1, -1))
rec = np.zeros((1, 1), dtype=[("X", object), ("Y", object), ("Description", object)])
rec[0, 0] = (X, Y, "ControlDesk recording")
savemat("dspace.mat", {"run_A": rec}, do_compression=True)

rows = [(t[i], x[i], F[i], aux[i], n16[i]) for i in range(n)]


def text(path, header, sep, fmt, crlf=False, comma=False):
    end = "\r\n" if crlf else "\n"
    with open(path, "w", newline="") as f:
        if header:
            f.write(sep.join(["t", "x", "F", "aux", "n16"]) + end)
        for row in rows:
            fields = [fmt(v) for v in row[:4]] + ["%d" % row[4]]
            if comma:
                fields = [s.replace(".", ",") for s in fields]
            f.write(sep.join(fields) + end)


e7 = lambda v: "%.7e" % v
text("tab.txt", True, "\t", repr)
text("space.dat", True, "  ", e7)
text("semicolon_comma.csv", True, ";", repr, comma=True)
text("crlf.csv", True, ",", repr, crlf=True)
text("no_header.txt", False, " ", e7)

# Broken on purpose.
with open("err_semicolon.csv", "w", newline="") as f:  # line 5: text in a number
    f.write("t;x;F;aux;n16\n")
    for i in range(6):
        v = "abc" if i == 3 else repr(F[i]).replace(".", ",")
        f.write("%s;%s;%s;%s;%d\n" % (repr(t[i]).replace(".", ","), repr(x[i]).replace(".", ","), v, "1", 0))
with open("err_crlf.csv", "w", newline="") as f:  # line 7: NaN, CRLF line ends
    f.write("t,x,F\r\n")
    for i in range(10):
        f.write("%s,%s,%s\r\n" % (repr(t[i]), repr(x[i]), "NaN" if i == 5 else repr(F[i])))
with open("err_mixed.txt", "w", newline="") as f:  # a comma-separated header over space-separated rows
    f.write("t,x,F\n")
    for i in range(5):
        f.write("%s %s %s\n" % (repr(t[i]), repr(x[i]), repr(F[i])))
