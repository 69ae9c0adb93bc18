//! What the standalone app (`sake-glug-standalone`) asks of the plugin it runs. nice-plug's
//! wrapper makes the plugin itself (`SakeGlug::default()`), so the app's own options reach it
//! through this process-wide setting, made once before the wrapper starts. In a DAW nothing sets
//! it and the plugin behaves as always.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, LazyLock, OnceLock};

use crate::device::Axis;

/// The standalone app's options for the plugin.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StandaloneOptions {
    /// Open the editor window; without it the app runs headless until SIGINT or SIGTERM.
    pub editor: bool,
    /// Listen for OSC on this UDP port with this bottle axis (overrides the saved setting).
    pub osc: Option<(u16, Axis)>,
}

static OPTIONS: OnceLock<StandaloneOptions> = OnceLock::new();
static QUIT: LazyLock<Arc<AtomicBool>> = LazyLock::new(Arc::default);
static PROCESSING: AtomicBool = AtomicBool::new(false);

/// Sets the options for this process; only the first call counts (returns whether it did).
pub fn configure(options: StandaloneOptions) -> bool {
    OPTIONS.set(options).is_ok()
}

/// The options, when running as the standalone app.
pub fn options() -> Option<&'static StandaloneOptions> {
    OPTIONS.get()
}

/// Whether the plugin should offer its editor (always, except in a headless standalone).
pub fn editor_wanted() -> bool {
    options().is_none_or(|options| options.editor)
}

/// Asks the editor window to close (a signal came): the app then ends as if it were closed.
pub fn request_quit() {
    QUIT.store(true, Ordering::Relaxed);
}

/// Whether [`request_quit`] was called or a quit signal came (see [`spawn_quit_watch`]).
pub fn quit_requested() -> bool {
    QUIT.load(Ordering::Relaxed)
}

/// Marks that `process()` has run: the wrapper is running and has installed its own signal
/// handler. Real-time safe (one relaxed atomic access).
pub fn mark_processing() {
    if !PROCESSING.load(Ordering::Relaxed) {
        PROCESSING.store(true, Ordering::Relaxed);
    }
}

/// In the standalone app: once the wrapper runs, makes SIGINT, SIGTERM and SIGHUP also ask the
/// editor to close (the wrapper's own handler, ctrlc's, only ends a headless run), and ends the
/// process `grace` after such a signal if the wrapper has not ended it by then. nice-plug's JACK
/// backend can wait for ever for the server to confirm the client's deactivation; the audio has
/// stopped by then, and the server drops the client when the process ends.
///
/// The handlers are added once `process()` has run (see [`mark_processing`]), so that they are
/// chained after ctrlc's, which replaces whatever handler it finds: both run.
#[cfg(all(feature = "standalone", unix))]
pub fn spawn_quit_watch(grace: std::time::Duration) {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    use std::time::Duration;
    let spawned = std::thread::Builder::new()
        .name("quit watch".into())
        .spawn(move || {
            while !PROCESSING.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(10));
            }
            for signal in [SIGINT, SIGTERM, SIGHUP] {
                if let Err(error) = signal_hook::flag::register(signal, QUIT.clone()) {
                    nice_plug::nice_error!("cannot watch signal {signal}: {error}");
                }
            }
            while !QUIT.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(10));
            }
            std::thread::sleep(grace);
            nice_plug::nice_warn!(
                "the audio backend did not stop within {grace:?} of the signal; exiting anyway"
            );
            std::process::exit(0);
        });
    if let Err(error) = spawned {
        nice_plug::nice_error!("cannot watch for quit signals: {error}");
    }
}
