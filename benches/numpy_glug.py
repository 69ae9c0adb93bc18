"""The same glug train synthesised unit by unit with NumPy: what a researcher would write.

Called by benches/render.rs as `python numpy_glug.py UNITS.f64 SAMPLES SAMPLE_RATE OUT.f32`.
UNITS.f64 holds one row of 8 little-endian f64 per unit, as the engine started them:
onset time (s), A1, A2 (a(V)·c and a(V)·(1 − c), before the gain), f1, f2, B1, B2 (Hz, 1/s),
and the output gain (dB) at the onset. Every component is summed in f64 from its first sample
after the onset until e^(−Bτ) < 1e-6 (MODEL.md §5–6), then the ceiling ±1 is applied.

Prints one line, `seconds=<synthesis time>`: the time of the synthesis alone, without reading
the units or writing the samples. The samples go to OUT.f32 so the bench can check that this is
the same train.
"""

import sys
import time

import numpy as np

SILENT_DECAY_EXPONENT = np.log(1e6)


def synthesise(units, samples, sample_rate):
    out = np.zeros(samples)
    for onset_s, a1, a2, f1, f2, b1, b2, gain_db in units:
        gain = 10.0 ** (gain_db / 20.0)
        first = int(np.floor(onset_s * sample_rate)) + 1
        for amplitude, frequency, decay in ((a1, f1, b1), (a2, f2, b2)):
            if amplitude == 0.0 or frequency >= 0.5 * sample_rate or first >= samples:
                continue
            length = samples - first
            if decay > 0.0:
                length = min(length, int(SILENT_DECAY_EXPONENT / decay * sample_rate) + 2)
            tau = (np.arange(first, first + length) / sample_rate) - onset_s
            out[first : first + length] += (
                gain * amplitude * np.exp(-decay * tau) * np.sin(2.0 * np.pi * frequency * tau)
            )
    return np.clip(out, -1.0, 1.0)


def main():
    units_path, samples, sample_rate, out_path = sys.argv[1:5]
    units = np.fromfile(units_path, dtype="<f8").reshape(-1, 8)
    samples, sample_rate = int(samples), float(sample_rate)
    start = time.perf_counter()
    out = synthesise(units, samples, sample_rate)
    seconds = time.perf_counter() - start
    out.astype("<f4").tofile(out_path)
    print(f"seconds={seconds}")


if __name__ == "__main__":
    main()
