"""The built-in pour through libsake_glug with nothing but Python's ctypes, written as a 48 kHz
mono 32-bit float WAV: the same samples as `sake-glug render -o pour.wav --sample-format f32`.

    cargo build --release -p sake-glug-c
    LD_LIBRARY_PATH=target/release python3 examples/python/pour.py pour.wav

The declarations follow include/sake_glug.h. `render_pour` takes any sample rate, e.g. 2000 Hz
for a controller's PCM haptics.
"""

import ctypes
import struct
import sys
from array import array

ABI_VERSION = 1
OK = 0
TILT = 0
BLOCK = 4096


class State(ctypes.Structure):
    _fields_ = [
        ("position", ctypes.c_uint64),
        ("active_until", ctypes.c_uint64),
        ("volume_ml", ctypes.c_double),
        ("outflow_ml_per_s", ctypes.c_double),
        ("tilt_deg", ctypes.c_double),
        ("output_gain", ctypes.c_double),
        ("submerged", ctypes.c_uint32),
        ("settled", ctypes.c_uint32),
        ("units", ctypes.c_uint32),
        ("units_lost", ctypes.c_uint32),
    ]


def load(name="libsake_glug.so"):
    """The library, found as the dynamic loader finds it (LD_LIBRARY_PATH), its calls typed."""
    lib = ctypes.CDLL(name)
    lib.sake_glug_abi_version.restype = ctypes.c_uint32
    lib.sake_glug_default_seed.restype = ctypes.c_uint64
    lib.sake_glug_status_text.argtypes = [ctypes.c_int32]
    lib.sake_glug_status_text.restype = ctypes.c_char_p
    lib.sake_glug_create.argtypes = [ctypes.c_double, ctypes.c_char_p, ctypes.c_uint64]
    lib.sake_glug_create.restype = ctypes.c_void_p
    lib.sake_glug_create_preset.argtypes = [ctypes.c_double, ctypes.c_char_p, ctypes.c_uint64]
    lib.sake_glug_create_preset.restype = ctypes.c_void_p
    lib.sake_glug_last_error.argtypes = [ctypes.c_char_p, ctypes.c_size_t]
    lib.sake_glug_last_error.restype = ctypes.c_size_t
    lib.sake_glug_destroy.argtypes = [ctypes.c_void_p]
    lib.sake_glug_destroy.restype = None
    for name, argtypes in [
        ("sake_glug_set", [ctypes.c_void_p, ctypes.c_int32, ctypes.c_double]),
        ("sake_glug_ramp", [ctypes.c_void_p, ctypes.c_int32, ctypes.c_double, ctypes.c_uint64]),
        ("sake_glug_process", [ctypes.c_void_p, ctypes.POINTER(ctypes.c_float), ctypes.c_size_t]),
        ("sake_glug_state", [ctypes.c_void_p, ctypes.POINTER(State)]),
    ]:
        function = getattr(lib, name)
        function.argtypes = argtypes
        function.restype = ctypes.c_int32
    if lib.sake_glug_abi_version() != ABI_VERSION:
        raise RuntimeError("libsake_glug is not the one this example was written for")
    return lib


def check(lib, status, what):
    if status != OK:
        raise RuntimeError(f"{what}: {lib.sake_glug_status_text(status).decode()}")


def render_pour(lib, sample_rate, model_text=None, preset=None):
    """The built-in scene (tilt 90° -> 135° over half a second, held until pouring stops and
    every unit has decayed) at `sample_rate`, in the paper's bottle, a model file's text or a
    shipped preset (its name, such as "syrup"): its samples as an array of float32."""
    seed = lib.sake_glug_default_seed()
    if preset is not None:
        glug = lib.sake_glug_create_preset(sample_rate, preset.encode(), seed)
    else:
        text = None if model_text is None else model_text.encode()
        glug = lib.sake_glug_create(sample_rate, text, seed)
    if not glug:
        message = ctypes.create_string_buffer(lib.sake_glug_last_error(None, 0) + 1)
        lib.sake_glug_last_error(message, len(message))
        raise RuntimeError(message.value.decode())
    try:
        check(lib, lib.sake_glug_set(glug, TILT, 90.0), "set")
        check(lib, lib.sake_glug_ramp(glug, TILT, 135.0, sample_rate // 2), "ramp")
        samples = array("f")
        block = (ctypes.c_float * BLOCK)()
        state = State()
        while True:
            check(lib, lib.sake_glug_process(glug, block, BLOCK), "process")
            samples.frombytes(bytes(block))
            check(lib, lib.sake_glug_state(glug, ctypes.byref(state)), "state")
            if state.settled:
                return samples[: state.active_until]
    finally:
        lib.sake_glug_destroy(glug)


def write_wav(path, samples, sample_rate):
    """A WAV of IEEE floats (format 3): RIFF, fmt and data chunks, little-endian."""
    data = struct.pack(f"<{len(samples)}f", *samples)
    header = b"RIFF" + struct.pack("<I", 36 + len(data)) + b"WAVEfmt "
    header += struct.pack("<IHHIIHH", 16, 3, 1, sample_rate, sample_rate * 4, 4, 32)
    with open(path, "wb") as file:
        file.write(header + b"data" + struct.pack("<I", len(data)) + data)


def main():
    if len(sys.argv) != 2:
        print("usage: pour.py OUT.wav", file=sys.stderr)
        sys.exit(2)
    sample_rate = 48000
    write_wav(sys.argv[1], render_pour(load(), sample_rate), sample_rate)


if __name__ == "__main__":
    main()
