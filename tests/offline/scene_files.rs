//! Scene files (MODEL.md §10): every fixture under valid/ parses; every one under invalid/ is
//! refused with the message its `# expect:` line gives.

use std::path::Path;

use sake_glug_engine::curves::BottleCurves;
use sake_glug_engine::{Curve, DrainMode, Glide, Headspace, ModelConfig, SilentBelow};
use sake_glug_render::{Automation, Scene, SceneError};

fn fixtures(kind: &str) -> Vec<(String, String)> {
    let directory = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/scenes")
        .join(kind);
    let mut files: Vec<_> = std::fs::read_dir(&directory)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|ext| ext == "toml"))
        .map(|path| {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&path).unwrap())
        })
        .collect();
    files.sort();
    assert!(
        files.len() >= 3,
        "fixtures missing in {}",
        directory.display()
    );
    files
}

#[test]
fn every_valid_fixture_parses() {
    for (name, text) in fixtures("valid") {
        if let Err(error) = Scene::parse(&text) {
            panic!("{name}: {error}");
        }
    }
}

#[test]
fn every_invalid_fixture_is_refused_with_its_message() {
    for (name, text) in fixtures("invalid") {
        let expected = text
            .lines()
            .find_map(|line| line.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{name} has no `# expect:` line"));
        match Scene::parse(&text) {
            Ok(_) => panic!("{name} was accepted"),
            Err(error) => {
                let message = error.to_string();
                assert!(
                    message.contains(expected),
                    "{name}: got\n{message}\nexpected {expected}"
                );
            }
        }
    }
}

fn full_fixture() -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scenes/valid/full.toml"),
    )
    .unwrap()
}

#[test]
fn the_full_fixture_reads_every_key_with_its_own_value() {
    let scene = Scene::parse(&full_fixture()).unwrap();
    let default = ModelConfig::default();
    assert_eq!(scene.sample_rate, 44_100);
    assert_eq!(scene.duration_s, Some(7.25));
    let points = |pairs: &[(f64, f64)]| Automation::Points(pairs.to_vec());
    assert_eq!(scene.lanes.tilt_deg, points(&[(0.0, 91.0), (0.75, 133.0)]));
    assert_eq!(scene.lanes.viscosity, points(&[(0.0, 0.61), (2.0, 0.47)]));
    assert_eq!(scene.lanes.fill_percent, Automation::Constant(88.5));
    assert_eq!(scene.lanes.pour_time_s, points(&[(0.0, 6.5), (1.0, 4.25)]));
    assert_eq!(scene.lanes.gain_db, points(&[(0.0, -9.5), (3.0, -3.0)]));
    assert_eq!(
        scene.config,
        ModelConfig {
            capacity_ml: 720.0,
            pocket_ml: 4.5,
            frequency_hz: [95.0, 280.0],
            decay_per_s: [52.0, 33.0],
            // deterministic = true sets every spread to zero...
            timing_jitter: 0.0,
            freq_jitter: 0.0,
            decay_sigma: 0.0,
            silent_below: SilentBelow::Ml(150.0),
            amplitude_spread: 0.0,
            headspace: Headspace {
                headspace_ml: 42.5,
                exponent: [0.5, -0.125],
            },
            glide: Glide {
                ratio: [1.6, 0.8],
                time_ms: [12.5, 35.0],
            },
            curves: BottleCurves {
                rest: Curve::Rest
                    .from_points(&[(60.0, 1.0), (90.0, 0.4), (120.0, 0.0)])
                    .unwrap(),
                submerged: Curve::Submerged
                    .from_points(&[(70.0, 0.9), (130.0, 0.0)])
                    .unwrap(),
                drain: Curve::Drain
                    .from_points(&[(45.0, 0.0), (135.0, 1.0), (180.0, 0.5)])
                    .unwrap(),
            },
            seed: 42,
            drain: DrainMode::Follow,
            ceiling: default.ceiling,
        }
    );
    // ...so the spreads are read from the same file without that line.
    let random = full_fixture().replace("deterministic = true\n", "");
    let scene = Scene::parse(&random).unwrap();
    assert_eq!(
        (
            scene.config.timing_jitter,
            scene.config.freq_jitter,
            scene.config.decay_sigma
        ),
        (0.21, 0.07, 0.5)
    );
    assert_eq!(scene.config.amplitude_spread, 0.25);
    // Every value differs from its default, so a key that is not read shows.
    assert_ne!(scene.config.timing_jitter, default.timing_jitter);
    assert_ne!(scene.config.freq_jitter, default.freq_jitter);
    assert_ne!(scene.config.decay_sigma, default.decay_sigma);
    assert_ne!(scene.config.amplitude_spread, default.amplitude_spread);
}

#[test]
fn a_fractional_sample_rate_is_refused_in_a_scene_and_as_an_override_alike() {
    let in_scene = Scene::parse("sample_rate = 48000.5")
        .unwrap_err()
        .to_string();
    let override_ = Scene::default()
        .with_sample_rate(48_000.5)
        .unwrap_err()
        .to_string();
    assert_eq!(in_scene, override_);
    assert!(in_scene.contains("`sample_rate` = 48000.5 is not a whole number"));
}

#[test]
fn a_missing_file_names_its_path() {
    let error = Scene::load(Path::new("/no/such/scene.toml")).unwrap_err();
    assert!(matches!(error, SceneError::Read { .. }));
    assert!(error.to_string().contains("/no/such/scene.toml"));
}
