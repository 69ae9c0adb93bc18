//! What the standalone app (`sake-glug-standalone`) asks of the plugin it runs. nice-plug's
//! wrapper makes the plugin itself (`SakeGlug::default()`), so the app's own options reach it
//! through this process-wide setting, made once before the wrapper starts. In a DAW nothing sets
//! it and the plugin behaves as always.

use std::net::IpAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, LazyLock, OnceLock};

use sake_glug_device::Axis;

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
    pub model: Option<sake_glug_model_file::ModelFile>,
    /// The actuator to compensate for (`--actuator`, `--felt`), as the editor's menu sets it.
    pub actuator: Option<crate::actuator_setting::Actuator>,
    /// The row of the MIDI settings that learns the device's first CC (`--learn`), as the
    /// editor's "Learn" button arms it.
    pub learn: Option<sake_glug_device::midi::MidiSetting>,
}

static OPTIONS: OnceLock<StandaloneOptions> = OnceLock::new();
static QUIT: LazyLock<Arc<AtomicBool>> = LazyLock::new(Arc::default);
/// `process()` calls so far (counted only in the standalone app).
static CYCLES: AtomicU64 = AtomicU64::new(0);
static EDITOR_WAKE: OnceLock<Box<dyn Fn() + Send + Sync>> = OnceLock::new();
/// The app's one plugin's parameters, for the app to report what MIDI learn took.
static PARAMS: OnceLock<Arc<crate::GlugParams>> = OnceLock::new();

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

/// Whether [`request_quit`] was called or a quit signal came (the app sets [`quit_flag`]).
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

/// Counts a `process()` call in the standalone app, so that the app's watch knows the wrapper
/// runs and the audio still comes ([`processing_cycles`]). Real-time safe (atomic accesses only).
pub fn mark_processing() {
    if OPTIONS.get().is_some() {
        CYCLES.fetch_add(1, Ordering::Relaxed);
    }
}

/// `process()` calls so far in the standalone app.
pub fn processing_cycles() -> u64 {
    CYCLES.load(Ordering::Relaxed)
}

/// The flag a quit signal sets (the app registers it for SIGINT, SIGTERM and SIGHUP).
pub fn quit_flag() -> Arc<AtomicBool> {
    QUIT.clone()
}

/// In the standalone app, keeps the plugin's parameters for [`last_learnt`]; the first
/// instance's only. In a DAW nothing is kept.
pub fn share_params(params: &Arc<crate::GlugParams>) {
    if options().is_some() {
        let _ = PARAMS.set(params.clone());
    }
}

/// The last CC that MIDI learn took in the standalone app, if any.
pub fn last_learnt() -> Option<crate::Learnt> {
    PARAMS.get()?.learn.last_learnt()
}
