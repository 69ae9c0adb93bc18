//! How much memory the files of a render will need, known before it starts, so that a render
//! that cannot fit is refused with the figure instead of aborting hours in.
//!
//! A WAV or CSV keeps nothing but a block; the clips and the plot keep every glug, so their need
//! is the most glugs the scene can start, which the pour's rates bound (MODEL.md §3, §4).

use super::scene::Scene;
use sake_glug_engine::pour::MAX_ONSETS_PER_SAMPLE;
use sake_glug_engine::DrainMode;

/// The most glugs `scene` can start. A unit starts each time a pocket of at least
/// b·(1 − j_t) has poured, at most C/T·max h(θ) ml/s (the fastest the lanes and a take can
/// pour) and never more than [`MAX_ONSETS_PER_SAMPLE`] a sample; that rate lasts the scene's
/// duration, or until its last automation point and then one more bottle (a scene without one
/// ends where it stops pouring). In simulate mode at a steady fill the bottle empties once, and
/// once more for every message of a take (each may refill it).
pub(crate) fn max_units(scene: &Scene) -> u64 {
    let config = &scene.config;
    let sample_rate = scene.sample_rate as f64;
    let shortest_pour_s = scene
        .lanes
        .pour_time_s
        .values()
        .fold(f64::INFINITY, f64::min);
    let smallest_pocket_ml = config.pocket_ml * (1.0 - config.timing_jitter);
    let fastest_ml_per_s = config.capacity_ml / shortest_pour_s * config.curves.drain.max();
    let units_per_s =
        (fastest_ml_per_s / smallest_pocket_ml).min(MAX_ONSETS_PER_SAMPLE as f64 * sample_rate);
    let bottles = |count: f64| count * config.capacity_ml / smallest_pocket_ml;
    let pouring = match scene.duration_s {
        Some(duration_s) => units_per_s * duration_s,
        None => units_per_s * scene.last_automation_s() + bottles(1.0),
    };
    let take_messages = scene.take.as_ref().map_or(0, |take| take.events.len());
    let steady_fill = matches!(scene.lanes.fill_percent, super::Automation::Constant(_));
    let units = if config.drain == DrainMode::Simulate && steady_fill {
        pouring.min(bottles(1.0 + take_messages as f64))
    } else {
        pouring
    };
    units.ceil().min(u64::MAX as f64) as u64 + 1
}

/// Memory the system can give a new process without swapping (Linux: `MemAvailable` of
/// `/proc/meminfo`); `None` where it cannot be told, and nothing is refused then.
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo
        .lines()
        .find_map(|line| line.strip_prefix("MemAvailable:"))?;
    let kilobytes: u64 = line.trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kilobytes.saturating_mul(1024))
}

/// A size in bytes for a person: "512 B", "1.5 kB", "12.3 MB", "8.6 GB", "2.1 TB".
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [(f64, &str); 4] = [(1e12, "TB"), (1e9, "GB"), (1e6, "MB"), (1e3, "kB")];
    UNITS
        .iter()
        .find(|&&(size, _)| bytes as f64 >= size)
        .map_or(format!("{bytes} B"), |&(size, unit)| {
            format!("{:.1} {unit}", bytes as f64 / size)
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bound_holds_and_is_not_far_off() {
        // Follow mode at 135°: the steady rate C/T/b = 300/5/0.1 = 600 glugs a second, which a
        // render of that scene comes within a few per cent of (35,953 in 60 s, without spread).
        let scene = Scene::parse(
            "duration_s = 60.0\ntilt_deg = 135.0\n[bottle]\npocket_ml = 0.1\n\
             [glug]\ntiming_jitter = 0.0\n[output]\ndrain = \"follow\"\n",
        )
        .unwrap();
        assert_eq!(max_units(&scene), 36_001);
        // Simulate mode at a steady fill: one bottle of 300 ml, not a day of pouring.
        let scene = Scene::parse(
            "duration_s = 86400.0\ntilt_deg = 135.0\n[bottle]\npocket_ml = 0.1\n\
             [glug]\ntiming_jitter = 0.0\n",
        )
        .unwrap();
        assert_eq!(max_units(&scene), 3_001);
        // Never more than MAX_ONSETS_PER_SAMPLE a sample, however fast the pour.
        let scene = Scene::parse(
            "duration_s = 1.0\ntilt_deg = 135.0\npour_time_s = 0.01\n[bottle]\npocket_ml = 0.001\n\
             [output]\ndrain = \"follow\"\n",
        )
        .unwrap();
        assert_eq!(max_units(&scene), 8 * 48_000 + 1);
    }

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(human_bytes(999), "999 B");
        assert_eq!(human_bytes(1_500), "1.5 kB");
        assert_eq!(human_bytes(985_876), "985.9 kB");
        assert_eq!(human_bytes(11_520_068), "11.5 MB");
        assert_eq!(human_bytes(8_589_934_592), "8.6 GB");
        assert_eq!(human_bytes(2_100_000_000_000), "2.1 TB");
    }
}
