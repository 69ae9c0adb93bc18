/* The built-in pour through libsake_glug, written as a 48 kHz mono 32-bit float WAV: the same
 * samples as `sake-glug render -o pour.wav --sample-format f32`.
 *
 *   cargo build --release -p sake-glug-c
 *   gcc -std=c11 -I include examples/c/pour.c -L target/release -lsake_glug -o pour
 *   LD_LIBRARY_PATH=target/release ./pour pour.wav
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sake_glug.h"

enum { SAMPLE_RATE = 48000, BLOCK = 4096 };

static int failed(const char *what, SakeGlugStatus status) {
    fprintf(stderr, "error: %s: %s\n", what, sake_glug_status_text(status));
    return 1;
}

static void little_endian(unsigned char *to, uint32_t value, int bytes) {
    for (int i = 0; i < bytes; i++) to[i] = (unsigned char)(value >> (8 * i));
}

/* A WAV of IEEE floats (format 3): RIFF, fmt and data chunks. */
static int write_wav(const char *path, const float *samples, size_t count) {
    unsigned char header[44];
    uint32_t data_bytes = (uint32_t)(count * 4);
    memcpy(header, "RIFF", 4);
    little_endian(header + 4, 36 + data_bytes, 4);
    memcpy(header + 8, "WAVEfmt ", 8);
    little_endian(header + 16, 16, 4);
    little_endian(header + 20, 3, 2);               /* IEEE float */
    little_endian(header + 22, 1, 2);               /* mono */
    little_endian(header + 24, SAMPLE_RATE, 4);
    little_endian(header + 28, SAMPLE_RATE * 4, 4); /* bytes per second */
    little_endian(header + 32, 4, 2);               /* bytes per frame */
    little_endian(header + 34, 32, 2);              /* bits per sample */
    memcpy(header + 36, "data", 4);
    little_endian(header + 40, data_bytes, 4);
    FILE *file = fopen(path, "wb");
    if (!file) return 0;
    int ok = fwrite(header, 1, sizeof header, file) == sizeof header;
    for (size_t i = 0; ok && i < count; i++) {
        uint32_t bits;
        unsigned char bytes[4];
        memcpy(&bits, &samples[i], 4);
        little_endian(bytes, bits, 4);
        ok = fwrite(bytes, 1, 4, file) == 4;
    }
    return fclose(file) == 0 && ok;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT.wav\n", argv[0]);
        return 2;
    }
    if (sake_glug_abi_version() != SAKE_GLUG_ABI_VERSION) {
        fprintf(stderr, "error: libsake_glug is not the one sake_glug.h describes\n");
        return 1;
    }
    SakeGlug *glug = sake_glug_create(SAMPLE_RATE, NULL, sake_glug_default_seed());
    if (!glug) {
        char message[1024];
        sake_glug_last_error(message, sizeof message);
        fprintf(stderr, "error: %s\n", message);
        return 1;
    }
    /* The built-in scene: tilt 90° -> 135° over half a second, then held. */
    SakeGlugStatus status = sake_glug_set(glug, SAKE_GLUG_CONTROL_TILT, 90.0);
    if (status != SAKE_GLUG_STATUS_OK) return failed("set", status);
    status = sake_glug_ramp(glug, SAKE_GLUG_CONTROL_TILT, 135.0, SAMPLE_RATE / 2);
    if (status != SAKE_GLUG_STATUS_OK) return failed("ramp", status);

    /* Until pouring stops and every unit has decayed; the samples end where the last one did. */
    float *samples = NULL;
    size_t count = 0;
    SakeGlugState state;
    do {
        float *grown = realloc(samples, (count + BLOCK) * sizeof *samples);
        if (!grown) {
            fprintf(stderr, "error: out of memory\n");
            return 1;
        }
        samples = grown;
        status = sake_glug_process(glug, samples + count, BLOCK);
        if (status != SAKE_GLUG_STATUS_OK) return failed("process", status);
        count += BLOCK;
        status = sake_glug_state(glug, &state);
        if (status != SAKE_GLUG_STATUS_OK) return failed("state", status);
    } while (!state.settled);
    sake_glug_destroy(glug);

    if (!write_wav(argv[1], samples, (size_t)state.active_until)) {
        perror(argv[1]);
        return 1;
    }
    free(samples);
    return 0;
}
