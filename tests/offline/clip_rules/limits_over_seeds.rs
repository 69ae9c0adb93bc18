//! Every format's limits hold over hundreds of seeds at full drive (`--haptic-peak 100%`, the
//! drive whose gain could round a clip a hair past full scale: issue 49, seed 811612), with an
//! actuator's compensation and without, and a true-peak ceiling holds exactly as the measured
//! figure is written.

use std::path::Path;

use sake_glug_render::loudness::{HapticPeak, LevelStage, LevelTarget};
use sake_glug_render::{
    render_scene, render_to_files, Output, OutputError, OutputFormat, OutputOptions, RenderError,
    Scene,
};

use super::{ahap, android_ogg, android_waveform, android_xml, dualsense, haps, haptic, rumble};

/// A short pour that glugs at once, so that hundreds of seeds render quickly.
const SHORT_SCENE: &str = "duration_s = 1.0\ntilt_deg = 140.0\n";

/// The seeds of a check: the two of the issue (on the default pour), then `count` more on
/// [`SHORT_SCENE`].
fn scenes(count: u64) -> impl Iterator<Item = Scene> {
    let issue = [811_612, 18].map(|seed| (sake_glug_render::DEFAULT_SCENE, seed));
    issue
        .into_iter()
        .chain((0..count).map(|seed| (SHORT_SCENE, seed)))
        .map(|(text, seed)| {
            let mut scene = Scene::parse(text).unwrap();
            scene.config.seed = seed;
            scene
        })
}

/// Violations as text, whatever the format's rules.
fn shown<R: std::fmt::Debug>(violations: Vec<super::Violation<R>>) -> Vec<String> {
    violations.iter().map(|v| format!("{v:?}")).collect()
}

/// Each clip format and its validator, by name.
fn validate(format: OutputFormat, path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap();
    let text = || String::from_utf8(bytes.clone()).unwrap();
    match format.name() {
        "haptic" => shown(haptic::validate(&text())),
        "ahap" => shown(ahap::validate(&text())),
        "haps" => shown(haps::validate(&text())),
        "android-xml" => shown(android_xml::validate(&text())),
        "android-waveform" => shown(android_waveform::validate(&text())),
        "rumble" => shown(rumble::validate(&text())),
        "dualsense" => shown(dualsense::validate(&bytes)),
        "android-ogg" => shown(android_ogg::validate(&bytes)),
        name => panic!("no validator for {name}"),
    }
}

#[test]
fn every_clip_format_stays_within_its_limits_at_full_drive_over_many_seeds() {
    let formats = [
        OutputFormat::HAPTIC,
        OutputFormat::AHAP,
        OutputFormat::HAPS,
        OutputFormat::ANDROID_XML,
        OutputFormat::ANDROID_WAVEFORM,
        OutputFormat::RUMBLE,
        OutputFormat::DUALSENSE,
        OutputFormat::ANDROID_OGG,
    ];
    let directory = tempfile::tempdir().unwrap();
    let outputs: Vec<Output> = formats
        .iter()
        .map(|&format| Output {
            format,
            path: directory.path().join(format.file_name("pour")),
        })
        .collect();
    let options = OutputOptions {
        haptic_peak: Some(HapticPeak::FULL),
        ..OutputOptions::default()
    };
    let mut checked = 0;
    for (index, mut scene) in scenes(300).enumerate() {
        // Every third with a profile, whose compensation the drive's gain comes after.
        if index % 3 == 2 {
            scene.actuator = Some(
                sake_glug_actuator::ActuatorProfile::shipped("lra")
                    .unwrap()
                    .response(),
            );
        }
        let seed = scene.config.seed;
        render_to_files(&scene, "pour", &outputs, &options, |_| {}).unwrap();
        for output in &outputs {
            let violations = validate(output.format, &output.path);
            assert!(
                violations.is_empty(),
                "seed {seed}, {}: {violations:#?}",
                output.format.name()
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 302);
}

/// A ceiling of −1 dBTP, with a loudness it holds back, over hundreds of seeds: the true peak
/// the files are measured at (the figure the summary and the manifests write) is never above
/// −1, not even by the last digit.
#[test]
fn a_true_peak_ceiling_holds_exactly_as_written_over_many_seeds() {
    let target = LevelTarget {
        loudness_lufs: Some(-10.0),
        true_peak_dbtp: Some(-1.0),
    };
    for scene in scenes(300) {
        let seed = scene.config.seed;
        let mut stage: LevelStage =
            LevelStage::new::<OutputError>(&scene, &target, true, &[], &|_: u64| {}).unwrap();
        render_scene(
            &scene,
            |block: &[f32]| {
                stage.apply(block);
                Ok::<(), RenderError>(())
            },
            &mut |_| {},
        )
        .unwrap();
        let written = stage.finish().unwrap().after.true_peak_dbtp;
        // As the manifests write it: the shortest text that reads back as the same f64.
        let text = written.to_string();
        assert!(
            text.parse::<f64>().unwrap() <= -1.0,
            "seed {seed}: a ceiling of -1 dBTP written as {text}"
        );
    }
}
