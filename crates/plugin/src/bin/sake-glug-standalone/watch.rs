//! What the app watches that nice-plug's wrapper does not: quit signals and the audio itself.
//! It lives in the app, not in the plugin's library: only the app may end its process.

use sake_glug_plugin::standalone;

/// How often the watch looks at the quit flag and the audio callbacks.
const WATCH_POLL: std::time::Duration = std::time::Duration::from_millis(10);

/// Once the wrapper runs, says on stderr what MIDI learn takes, and watches two things
/// nice-plug's wrapper does not:
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
pub fn spawn_watch(grace: std::time::Duration, audio_lost_after: std::time::Duration) {
    let spawned = std::thread::Builder::new()
        .name("app watch".into())
        .spawn(move || {
            while standalone::processing_cycles() == 0 {
                std::thread::sleep(WATCH_POLL);
            }
            watch_signals();
            let silent_polls_allowed = audio_lost_after.as_millis() / WATCH_POLL.as_millis();
            let (mut cycles, mut silent_polls) = (0, 0);
            let mut learnt_shown = None;
            while !standalone::quit_requested() {
                std::thread::sleep(WATCH_POLL);
                // What MIDI learn took, said once (the audio thread cannot print).
                let learnt = standalone::last_learnt();
                if learnt != learnt_shown {
                    if let Some(learnt) = learnt {
                        eprintln!("MIDI learn: {learnt}");
                    }
                    learnt_shown = learnt;
                }
                let now = standalone::processing_cycles();
                silent_polls = if now == cycles { silent_polls + 1 } else { 0 };
                cycles = now;
                if silent_polls > silent_polls_allowed && !standalone::quit_requested() {
                    nice_plug::nice_error!(
                        "the audio stopped: no audio callback for {audio_lost_after:?} (the JACK \
                         server or the audio device went away); exiting"
                    );
                    std::process::exit(1);
                }
            }
            standalone::request_quit();
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
fn watch_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    for signal in [SIGINT, SIGTERM, SIGHUP] {
        if let Err(error) = signal_hook::flag::register(signal, standalone::quit_flag()) {
            nice_plug::nice_error!("cannot watch signal {signal}: {error}");
        }
    }
}
