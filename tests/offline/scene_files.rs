//! Scene files (MODEL.md §10): every fixture under valid/ parses; every one under invalid/ is
//! refused with the message its `# expect:` line gives.

use std::path::Path;

use sake_glug::engine::{DrainMode, ModelConfig};
use sake_glug::offline::{Automation, Scene, SceneError};

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

#[test]
fn the_full_fixture_reads_every_key() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/scenes/valid/full.toml"),
    )
    .unwrap();
    let scene = Scene::parse(&text).unwrap();
    assert_eq!(scene.sample_rate, 48_000);
    assert_eq!(scene.duration_s, Some(8.0));
    assert_eq!(
        scene.tilt_deg,
        Automation::Points(vec![(0.0, 90.0), (0.5, 135.0)])
    );
    assert_eq!(scene.config, ModelConfig::default());
    let changed = Scene::parse(
        "seed = 9\ndeterministic = true\n[bottle]\ncapacity_ml = 720.0\n[glug]\nf2_hz = 250.0\n[output]\ndrain = \"follow\"",
    )
    .unwrap();
    assert_eq!(changed.config.seed, 9);
    assert_eq!(changed.config.capacity_ml, 720.0);
    assert_eq!(changed.config.frequency_hz, [80.0, 250.0]);
    assert_eq!(changed.config.drain, DrainMode::Follow);
    assert_eq!(
        (
            changed.config.timing_jitter,
            changed.config.freq_jitter,
            changed.config.decay_sigma
        ),
        (0.0, 0.0, 0.0)
    );
}

#[test]
fn a_missing_file_names_its_path() {
    let error = Scene::load(Path::new("/no/such/scene.toml")).unwrap_err();
    assert!(matches!(error, SceneError::Read { .. }));
    assert!(error.to_string().contains("/no/such/scene.toml"));
}
