//! What a render keeps in memory: a WAV-only render holds nothing per glug, however many glugs
//! it starts (a clip or the plot keeps each, and is refused up front if they cannot fit).

use std::process::{Command, Stdio};
use std::time::Duration;

/// The peak resident memory (kB) of `sake-glug ARGS` in `directory`, as last seen in
/// `/proc/<pid>/status` (`VmHWM` only grows) while it ran.
#[cfg(target_os = "linux")]
fn peak_rss_kb(directory: &std::path::Path, args: &[&str]) -> u64 {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(directory)
        .args(args)
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let status = format!("/proc/{}/status", child.id());
    let mut peak = None;
    while child.try_wait().unwrap().is_none() {
        let text = std::fs::read_to_string(&status).unwrap_or_default();
        let high_water = text
            .lines()
            .find_map(|line| line.strip_prefix("VmHWM:"))
            .and_then(|value| value.trim().trim_end_matches("kB").trim().parse().ok());
        peak = high_water.or(peak);
        std::thread::sleep(Duration::from_millis(2));
    }
    assert!(child.wait().unwrap().success());
    peak.expect("the render ended before its memory could be read")
}

#[cfg(target_os = "linux")]
#[test]
fn a_wav_only_render_keeps_nothing_per_glug() {
    let directory = tempfile::tempdir().unwrap();
    // 60,000 glugs a second: 240,000 in 4 s, which would take 15 MB more if kept.
    for seconds in [0.5, 4.0] {
        let scene = format!(
            "duration_s = {seconds}\ntilt_deg = 135.0\npour_time_s = 0.05\n\
             [bottle]\npocket_ml = 0.1\n[output]\ndrain = \"follow\"\n"
        );
        std::fs::write(directory.path().join(format!("{seconds}.toml")), scene).unwrap();
    }
    let short = peak_rss_kb(directory.path(), &["render", "0.5.toml", "-o", "short.wav"]);
    let long = peak_rss_kb(directory.path(), &["render", "4.toml", "-o", "long.wav"]);
    assert!(
        long < short + 4 * 1024,
        "{short} kB for 0.5 s, {long} kB for 4 s"
    );
}
