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

/// Whether [`request_quit`] was called or a quit signal came (see [`watch_quit_signals`]).
pub fn quit_requested() -> bool {
    QUIT.load(Ordering::Relaxed)
}

/// In the standalone app, makes SIGINT, SIGTERM and SIGHUP ask the editor to close. The
/// wrapper's own handler (ctrlc) only ends a headless run, not one with a window; this one is
/// chained to it, so both still run. Call it once the wrapper runs (the editor does, when it
/// opens); does nothing outside the standalone app or a second time.
pub fn watch_quit_signals() {
    #[cfg(all(feature = "standalone", unix))]
    {
        static WATCHING: std::sync::Once = std::sync::Once::new();
        if options().is_some() {
            WATCHING.call_once(|| {
                use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
                for signal in [SIGINT, SIGTERM, SIGHUP] {
                    if let Err(error) = signal_hook::flag::register(signal, QUIT.clone()) {
                        nice_plug::nice_error!("cannot watch signal {signal}: {error}");
                    }
                }
            });
        }
    }
}
