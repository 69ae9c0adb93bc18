// libsake_glug for C++17, header-only: a handle that frees itself (RAII) over sake_glug.h.
//
// Creating a Glug throws sake_glug::Error with the library's message (creation allocates, and
// is never done on the audio thread anyway). The calls of the audio thread and the control calls
// are noexcept and answer with a Status, because throwing allocates and the real-time rules of
// sake_glug.h forbid that; check them with ok() or throw_if_failed() where it is allowed.
#ifndef SAKE_GLUG_HPP
#define SAKE_GLUG_HPP

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sake_glug.h"

namespace sake_glug {

using Status = SakeGlugStatus;
using State = SakeGlugState;
using Unit = SakeGlugUnit;
using Range = SakeGlugRange;

enum class Control : int32_t {
    Tilt = SAKE_GLUG_CONTROL_TILT,
    Viscosity = SAKE_GLUG_CONTROL_VISCOSITY,
    Fill = SAKE_GLUG_CONTROL_FILL,
    PourTime = SAKE_GLUG_CONTROL_POUR_TIME,
    Gain = SAKE_GLUG_CONTROL_GAIN,
};

inline bool ok(Status status) noexcept { return status == SAKE_GLUG_STATUS_OK; }

// A status that is not ok, or a handle that could not be made.
class Error : public std::runtime_error {
  public:
    explicit Error(const std::string &message, Status status = SAKE_GLUG_STATUS_OK)
        : std::runtime_error(message), status_(status) {}
    Status status() const noexcept { return status_; }

  private:
    Status status_;
};

inline void throw_if_failed(Status status, const char *what) {
    if (!ok(status)) {
        throw Error(std::string(what) + ": " + sake_glug_status_text(status), status);
    }
}

// A control's range and default, from the engine.
inline Range range_of(Control control) {
    Range range{};
    throw_if_failed(sake_glug_control_range(static_cast<int32_t>(control), &range), "range");
    return range;
}

class Glug {
  public:
    // The paper's bottle, or the model file whose text is `model_text`; throws Error.
    explicit Glug(double sample_rate, const char *model_text = nullptr,
                  uint64_t seed = sake_glug_default_seed())
        : Glug(sake_glug_create(sample_rate, model_text, seed), Created{}) {}

    // A shipped preset by name (a file name of presets/ without .toml, such as "syrup"); throws
    // Error, whose message lists the presets if the name is unknown.
    static Glug preset(double sample_rate, const char *name,
                       uint64_t seed = sake_glug_default_seed()) {
        return Glug(sake_glug_create_preset(sample_rate, name, seed), Created{});
    }

    // Any thread; real-time safe.
    Status set(Control control, double value) noexcept {
        return sake_glug_set(get(), static_cast<int32_t>(control), value);
    }
    Status ramp(Control control, double target, uint64_t samples) noexcept {
        return sake_glug_ramp(get(), static_cast<int32_t>(control), target, samples);
    }
    Status refill() noexcept { return sake_glug_refill(get()); }
    Status reset() noexcept { return sake_glug_reset(get()); }

    // The audio thread; real-time safe.
    Status process(float *out, std::size_t frames) noexcept {
        return sake_glug_process(get(), out, frames);
    }
    Status process_interleaved(float *out, std::size_t frames, std::size_t channels) noexcept {
        return sake_glug_process_interleaved(get(), out, frames, channels);
    }
    Status state(State &state) noexcept { return sake_glug_state(get(), &state); }
    // The units first heard in the last process call, into `units` (its capacity is kept:
    // reserve SAKE_GLUG_MAX_UNITS once, off the audio thread, and this never allocates).
    Status units(std::vector<Unit> &units) noexcept {
        units.resize(units.capacity());
        std::size_t count = 0;
        Status status = sake_glug_units(get(), units.data(), units.size(), &count);
        units.resize(ok(status) ? count : 0);
        return status;
    }

    SakeGlug *get() const noexcept { return glug_.get(); }

  private:
    struct Created {};
    // Owns what a create call returned; throws its message if that was NULL.
    Glug(SakeGlug *glug, Created) : glug_(glug) {
        if (sake_glug_abi_version() != SAKE_GLUG_ABI_VERSION) {
            throw Error("libsake_glug is not the one sake_glug.h describes");
        }
        if (!glug_) {
            std::string message(sake_glug_last_error(nullptr, 0) + 1, '\0');
            sake_glug_last_error(&message[0], message.size());
            message.pop_back();
            throw Error(message);
        }
    }

    struct Destroy {
        void operator()(SakeGlug *glug) const noexcept { sake_glug_destroy(glug); }
    };
    std::unique_ptr<SakeGlug, Destroy> glug_;
};

}  // namespace sake_glug

#endif
