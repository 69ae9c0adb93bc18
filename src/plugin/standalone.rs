//! What the standalone app (`sake-glug-standalone`) asks of the plugin it runs. nice-plug's
//! wrapper makes the plugin itself (`SakeGlug::default()`), so the app's own options reach it
//! through this process-wide setting, made once before the wrapper starts. In a DAW nothing sets
//! it and the plugin behaves as always.

use std::net::IpAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, LazyLock, OnceLock};

use crate::device::Axis;

/// The standalone app's options for the plugin.
#[derive(Debug, Clone, PartialEq)]
pub struct StandaloneOptions {
    /// Open the editor window; without it the app runs headless until SIGINT or SIGTERM.
    pub editor: bool,
    /// Listen for OSC on this UDP port with this bottle axis (overrides the saved setting): the
    /// user's own choice, so the port opens at once.
    pub osc: Option<(u16, Axis)>,
    /// The address the OSC socket binds to, whenever OSC is turned on in this session.
    pub osc_interface: IpAddr,
    /// The model file to start with (`--model`), loaded as the editor's "Load model…" loads it.
    pub model: Option<crate::model::Model>,
}

static OPTIONS: OnceLock<StandaloneOptions> = OnceLock::new();
static QUIT: LazyLock<Arc<AtomicBool>> = LazyLock::new(Arc::default);
/// `process()` calls so far (counted only in the standalone app).
static CYCLES: AtomicU64 = AtomicU64::new(0);
static EDITOR_WAKE: OnceLock<Box<dyn Fn() + Send + Sync>> = OnceLock::new();

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
    if let Some(wake) = EDITOR_WAKE.get() {
        wake();
    }
}

/// Whether [`request_quit`] was called or a quit signal came (see [`spawn_watch`]).
pub fn quit_requested() -> bool {
    QUIT.load(Ordering::Relaxed)
}

/// In the standalone app, lets a quit wake the editor: an idle window draws nothing, so it
/// would not look at [`quit_requested`] until something else changed. Only the first call
/// counts; in a DAW nothing is kept.
pub fn wake_editor_with(wake: impl Fn() + Send + Sync + 'static) {
    if options().is_some() {
        let _ = EDITOR_WAKE.set(Box::new(wake));
    }
}

/// Counts a `process()` call in the standalone app, so that [`spawn_watch`] knows the wrapper
/// runs and the audio still comes. Real-time safe (atomic accesses only).
pub fn mark_processing() {
    if OPTIONS.get().is_some() {
        CYCLES.fetch_add(1, Ordering::Relaxed);
    }
}

/// How often the watch looks at the quit flag and the audio callbacks.
#[cfg(all(feature = "standalone", unix))]
const WATCH_POLL: std::time::Duration = std::time::Duration::from_millis(10);

/// In the standalone app, once the wrapper runs, watches two things nice-plug's wrapper does not:
///
/// - Quit signals, however many come. SIGINT, SIGTERM and SIGHUP also ask the editor to close
///   (the wrapper's own handler, ctrlc's, only ends a headless run), and the process ends `grace`
///   after the first of them if the wrapper has not ended it by then. nice-plug's JACK backend
///   deactivates its client twice at once when it stops (its process callback returns `Quit`,
///   which makes libjack deactivate the client from the audio thread, while the wrapper's thread
///   deactivates it too), and the two requests on one socket can stall each other for seconds.
///   The audio has stopped by then, and the server drops the client when the process ends.
/// - The audio. If `process()` is not called for `audio_lost_after` (the JACK server went away,
///   or the audio device), the wrapper would wait for ever, silent: the watch says so on stderr
///   and ends the process with exit status 1.
///
/// The signal handlers are added once `process()` has run, so that they are chained after
/// ctrlc's, which replaces whatever handler it finds: both run. The watch counts its own polls
/// rather than reading a clock, so a process stopped and continued (SIGSTOP) is not mistaken for
/// lost audio.
#[cfg(all(feature = "standalone", unix))]
pub fn spawn_watch(grace: std::time::Duration, audio_lost_after: std::time::Duration) {
    let spawned = std::thread::Builder::new()
        .name("app watch".into())
        .spawn(move || {
            while CYCLES.load(Ordering::Relaxed) == 0 {
                std::thread::sleep(WATCH_POLL);
            }
            watch_signals();
            let silent_polls_allowed = audio_lost_after.as_millis() / WATCH_POLL.as_millis();
            let (mut cycles, mut silent_polls) = (0, 0);
            while !quit_requested() {
                std::thread::sleep(WATCH_POLL);
                let now = CYCLES.load(Ordering::Relaxed);
                silent_polls = if now == cycles { silent_polls + 1 } else { 0 };
                cycles = now;
                if silent_polls > silent_polls_allowed && !quit_requested() {
                    nice_plug::nice_error!(
                        "the audio stopped: no audio callback for {audio_lost_after:?} (the JACK \
                         server or the audio device went away); exiting"
                    );
                    std::process::exit(1);
                }
            }
            request_quit();
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

/// Makes SIGINT, SIGTERM and SIGHUP set the quit flag.
#[cfg(all(feature = "standalone", unix))]
fn watch_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    for signal in [SIGINT, SIGTERM, SIGHUP] {
        if let Err(error) = signal_hook::flag::register(signal, QUIT.clone()) {
            nice_plug::nice_error!("cannot watch signal {signal}: {error}");
        }
    }
}
