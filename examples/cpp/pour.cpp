// The built-in pour through include/sake_glug.hpp, written as a 48 kHz mono 32-bit float WAV:
// the same samples as `sake-glug render -o pour.wav --sample-format f32`.
//
//   cargo build --release -p sake-glug-c
//   g++ -std=c++17 -I include examples/cpp/pour.cpp -L target/release -lsake_glug -o pour
//   LD_LIBRARY_PATH=target/release ./pour pour.wav
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iostream>
#include <vector>

#include "sake_glug.hpp"

namespace {

constexpr uint32_t kSampleRate = 48000;
constexpr std::size_t kBlock = 4096;

void put(std::ofstream &file, uint32_t value, int bytes) {
    for (int i = 0; i < bytes; i++) file.put(static_cast<char>(value >> (8 * i)));
}

// A WAV of IEEE floats (format 3): RIFF, fmt and data chunks, little-endian.
bool write_wav(const char *path, const std::vector<float> &samples) {
    std::ofstream file(path, std::ios::binary);
    const auto data_bytes = static_cast<uint32_t>(samples.size() * 4);
    file.write("RIFF", 4);
    put(file, 36 + data_bytes, 4);
    file.write("WAVEfmt ", 8);
    put(file, 16, 4);
    put(file, 3, 2);  // IEEE float
    put(file, 1, 2);  // mono
    put(file, kSampleRate, 4);
    put(file, kSampleRate * 4, 4);
    put(file, 4, 2);
    put(file, 32, 2);
    file.write("data", 4);
    put(file, data_bytes, 4);
    for (float sample : samples) {
        uint32_t bits;
        std::memcpy(&bits, &sample, 4);
        put(file, bits, 4);
    }
    file.close();
    return static_cast<bool>(file);
}

}  // namespace

int main(int argc, char **argv) {
    if (argc != 2) {
        std::cerr << "usage: " << argv[0] << " OUT.wav\n";
        return 2;
    }
    try {
        using sake_glug::Control;
        using sake_glug::throw_if_failed;
        sake_glug::Glug glug(kSampleRate);
        // The built-in scene: tilt 90° -> 135° over half a second, then held.
        throw_if_failed(glug.set(Control::Tilt, 90.0), "set");
        throw_if_failed(glug.ramp(Control::Tilt, 135.0, kSampleRate / 2), "ramp");
        // Until pouring stops and every unit has decayed; the samples end where the last did.
        std::vector<float> samples;
        sake_glug::State state{};
        do {
            samples.resize(samples.size() + kBlock);
            throw_if_failed(glug.process(samples.data() + samples.size() - kBlock, kBlock),
                            "process");
            throw_if_failed(glug.state(state), "state");
        } while (!state.settled);
        samples.resize(state.active_until);
        if (!write_wav(argv[1], samples)) {
            std::cerr << "error: cannot write " << argv[1] << "\n";
            return 1;
        }
    } catch (const sake_glug::Error &error) {
        std::cerr << "error: " << error.what() << "\n";
        return 1;
    }
    return 0;
}
