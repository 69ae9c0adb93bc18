"""The units of a recording fitted one by one with SciPy's curve_fit: what a researcher would write.

Called by benches/render.rs as `python scipy_fit.py UNITS.f64 WINDOWS.f64 SAMPLE_RATE OUT.f64`.
UNITS.f64 holds one row of 10 little-endian f64 per unit: the first sample of its window, the
number of samples given, the stride between them (every k-th sample of the recording), and the
seven numbers `sake-glug fit` started its Levenberg-Marquardt from (onset s, A1, A2, f1, f2, B1,
B2). WINDOWS.f64 holds the windows' samples one after the other:
the recording less the units fitted before (as `sake-glug fit` sees them, MODEL.md §13).

Each window is fitted with eq. 1 (MODEL.md §5), q(τ) = A1·e^(−B1τ)·sin(2πf1τ) +
A2·e^(−B2τ)·sin(2πf2τ) from the onset on and 0 before it, by `curve_fit` (MINPACK's
Levenberg-Marquardt) from the same start, given the analytic Jacobian: the same problem handed to
both solvers. A unit curve_fit cannot fit is a row of NaN in OUT.f64 (7 f64 per unit).

Prints one line, `seconds=<time>`: the fits alone, without reading or writing the files.
"""

import sys
import time

import numpy as np
from scipy.optimize import curve_fit

TWO_PI = 2.0 * np.pi


def eq1(t, onset, a1, a2, f1, f2, b1, b2):
    tau = np.maximum(t - onset, 0.0)
    q = a1 * np.exp(-b1 * tau) * np.sin(TWO_PI * f1 * tau) + a2 * np.exp(-b2 * tau) * np.sin(
        TWO_PI * f2 * tau
    )
    return np.where(t >= onset, q, 0.0)


def eq1_jacobian(t, onset, a1, a2, f1, f2, b1, b2):
    on = t >= onset
    tau = np.where(on, t - onset, 0.0)
    columns = [np.zeros_like(t)]
    rows = {}
    for a, f, b, name in ((a1, f1, b1, 1), (a2, f2, b2, 2)):
        envelope = np.exp(-b * tau)
        sine = envelope * np.sin(TWO_PI * f * tau)
        cosine = envelope * np.cos(TWO_PI * f * tau)
        columns[0] = columns[0] - a * (TWO_PI * f * cosine - b * sine)
        rows[name] = (sine, a * TWO_PI * tau * cosine, -a * tau * sine)
    jacobian = np.column_stack(
        [
            columns[0],
            rows[1][0],
            rows[2][0],
            rows[1][1],
            rows[2][1],
            rows[1][2],
            rows[2][2],
        ]
    )
    jacobian[~on] = 0.0
    return jacobian


def fit_all(units, windows, sample_rate):
    fitted = np.full((len(units), 7), np.nan)
    offset = 0
    for index, row in enumerate(units):
        first, length, stride = int(row[0]), int(row[1]), int(row[2])
        data = windows[offset : offset + length]
        offset += length
        t = (first + stride * np.arange(length)) / sample_rate
        try:
            params, _ = curve_fit(eq1, t, data, p0=row[3:10], jac=eq1_jacobian, method="lm")
        except (RuntimeError, ValueError):
            continue
        fitted[index] = params
    return fitted


def main():
    units_path, windows_path, sample_rate, out_path = sys.argv[1:5]
    units = np.fromfile(units_path, dtype="<f8").reshape(-1, 10)
    windows = np.fromfile(windows_path, dtype="<f8")
    start = time.perf_counter()
    fitted = fit_all(units, windows, float(sample_rate))
    seconds = time.perf_counter() - start
    fitted.astype("<f8").tofile(out_path)
    print(f"seconds={seconds}")


if __name__ == "__main__":
    main()
