//! The presets as scene files: `presets/<id>.toml` is the code's own text for each preset (so
//! the files cannot drift from the plugin's menu), and it renders that preset.

use std::path::Path;

use sake_glug_engine::{ControlValues, ModelConfig, Preset, PRESETS};
use sake_glug_render::Scene;

#[test]
fn every_preset_file_is_the_presets_own_scene() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets");
    for preset in &PRESETS {
        let path = folder.join(format!("{}.toml", preset.id));
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|error| panic!("{}: {error} (run `cargo xtask docs`)", path.display()));
        assert_eq!(
            text,
            Scene::preset_toml(preset),
            "{} is stale",
            path.display()
        );
        let scene = Scene::load(&path).unwrap();
        assert_eq!(scene.config, preset.config(ModelConfig::default()));
        let values = scene.values_at(48_000);
        let tilted = ControlValues {
            tilt_deg: 135.0,
            ..ControlValues::default()
        };
        assert_eq!(values, preset.controls(tilted));
    }
    let scene_files = std::fs::read_dir(&folder)
        .unwrap()
        .filter(|entry| {
            let path = entry.as_ref().unwrap().path();
            path.extension()
                .is_some_and(|extension| extension == "toml")
        })
        .count();
    assert_eq!(scene_files, PRESETS.len(), "no scene file without a preset");
}

#[test]
fn presets_differ_where_they_should() {
    let default = ControlValues::default();
    let config = ModelConfig::default();
    let preset = |id: &str| Preset::find(id).unwrap();
    let viscosity = |id: &str| preset(id).controls(default).viscosity;
    assert_eq!(viscosity("water"), 0.33);
    assert_eq!(viscosity("thin"), 0.29);
    assert_eq!(viscosity("thick"), 0.42);
    let capacity = |id: &str| preset(id).config(config).capacity_ml;
    assert!(capacity("small-bottle") < 300.0 && capacity("large-bottle") > 300.0);
}

/// The threshold presets change c alone: every other control and constant is water's, so a
/// study of them presents one cue (issue 18: `thick` once also poured in 7 s instead of 5).
#[test]
fn the_threshold_presets_change_viscosity_alone() {
    let water = Preset::find("water").unwrap();
    for id in ["thin", "thick"] {
        let preset = Preset::find(id).unwrap();
        let mut controls = preset.controls(ControlValues::default());
        assert_ne!(
            controls.viscosity,
            water.controls(ControlValues::default()).viscosity
        );
        controls.viscosity = water.controls(ControlValues::default()).viscosity;
        assert_eq!(controls, water.controls(ControlValues::default()), "{id}");
        assert_eq!(
            preset.config(ModelConfig::default()),
            water.config(ModelConfig::default()),
            "{id}"
        );
    }
}
