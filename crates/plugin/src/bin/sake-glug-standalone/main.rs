//! `sake-glug-standalone`: the plugin as an application, without a DAW: MIDI from the tilt
//! device, OSC from a phone, the glug to the audio interface, the editor in a window.
//!
//! nice-plug's standalone wrapper parses its own options (`--backend jack|alsa`, ports, devices;
//! see `--help`). Ours are taken out of the command line first and the rest is handed to the
//! wrapper:
//!
//! - `--osc-port PORT`: listen for OSC on UDP PORT;
//! - `--osc-bind ADDRESS`: the address OSC listens on, 127.0.0.1 (this computer only) unless
//!   asked (`0.0.0.0`: every network interface);
//! - `--osc-axis AXIS`: the sensor axis from the bottle's base to its mouth (`+y` by default);
//! - `--version` (`-V`): print the version and quit;
//! - `--no-editor`: no window (no display needed); quit with Ctrl-C, SIGTERM or SIGHUP;
//! - `--model MODEL.toml`: play a model file's bottle and liquid (MODEL.md §12.1); a model that
//!   is refused ends the app at once (status 2) with the reason;
//! - `--actuator NAME|PROFILE.toml [--felt]`: compensate for an actuator (MODEL.md §18), as the
//!   editor's Actuator menu does; a profile that is refused ends the app at once (status 2);
//! - `--learn ROW`: MIDI learn without the editor: the first CC the device sends is taken for
//!   that row of the MIDI settings (`tilt`, `tilt_lsb`, `viscosity`, `fill`), with its channel,
//!   and printed on stderr (`MIDI learn: Tilt CC (MSB) = CC 20 on channel 4`).
//!
//! If the audio stops coming (the JACK server or the audio device went away) the app says so and
//! exits with status 1.

mod args;
#[cfg(unix)]
mod watch;

use std::process::ExitCode;
#[cfg(unix)]
use std::time::Duration;

use nice_plug::prelude::nice_export_standalone_with_args;
use sake_glug_model_file::ModelFile;
use sake_glug_plugin::standalone::{self, StandaloneOptions};
use sake_glug_plugin::Actuator;
use sake_glug_plugin::SakeGlug;

/// How long the wrapper gets to stop after a quit signal before the process ends anyway (it
/// takes a few tens of milliseconds when the audio server answers).
#[cfg(unix)]
const QUIT_GRACE: Duration = Duration::from_millis(250);
/// How long without an audio callback means that the audio server or device went away (longer
/// than any period a JACK server or an ALSA device runs at).
#[cfg(unix)]
const AUDIO_LOST_AFTER: Duration = Duration::from_secs(1);

fn main() -> ExitCode {
    let (own, wrapper_args) = args::split(std::env::args());
    // The wrapper knows no version; a release's products all report the workspace's.
    if wrapper_args
        .iter()
        .any(|arg| arg == "--version" || arg == "-V")
    {
        println!("sake-glug-standalone {}", env!("CARGO_PKG_VERSION"));
        return ExitCode::SUCCESS;
    }
    let options = match args::parse(&own) {
        Ok(options) => options,
        Err(error) => error.exit(),
    };
    if wrapper_args
        .iter()
        .any(|arg| arg == "--help" || arg == "-h")
    {
        println!("{}\n", args::help());
    }
    let model = match options.model.as_deref().map(ModelFile::load).transpose() {
        Ok(model) => model,
        Err(error) => {
            eprintln!("error: --model: {error}");
            return ExitCode::from(2);
        }
    };
    let actuator = match options.actuator.as_deref() {
        None => None,
        Some(name_or_path) => match Actuator::find(name_or_path, options.felt) {
            Ok(actuator) => Some(actuator),
            Err(error) => {
                eprintln!("error: --actuator: {error}");
                return ExitCode::from(2);
            }
        },
    };
    standalone::configure(StandaloneOptions {
        editor: !options.no_editor,
        osc: options.osc_port.map(|port| (port, options.osc_axis)),
        osc_interface: options.osc_bind,
        model,
        actuator,
        learn: options.learn,
    });
    #[cfg(unix)]
    watch::spawn_watch(QUIT_GRACE, AUDIO_LOST_AFTER);
    if nice_export_standalone_with_args::<SakeGlug, _>(wrapper_args) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
