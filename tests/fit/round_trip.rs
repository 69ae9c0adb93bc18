//! Known models rendered, fitted, and found again. Tolerances (MODEL.md §13): f within 2 %, c
//! within 0.02, B within 15 %, outflow rates within 2 %, V0 within 5 ml.

use sake_glug_fit::{write_fit, FitOutputs};
use sake_glug_render::Scene;

use super::*;

fn close(what: &str, value: f64, truth: f64, tolerance: f64) {
    assert!(
        (value - truth).abs() <= tolerance,
        "{what}: fitted {value}, truth {truth}, allowed ±{tolerance}"
    );
}

fn relative(what: &str, value: f64, truth: f64, share: f64) {
    close(what, value, truth, share * truth.abs());
}

/// The paper's bottle at 135° from full, at 25 kHz with a weight log and noise 30 dB below the
/// glugs: the fit gives back fig. 7's zero (84.33 ml), 60 ml/s and the model's constants.
#[test]
fn the_default_render_gives_back_the_papers_figures() {
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nseed = 7\n");
    let folder = tempfile::tempdir().unwrap();
    let take = Take {
        name: "pour135",
        rendered: &rendered,
        tilt_deg: 135.0,
        liquid: None,
        weight: true,
        noise_db: Some(-30.0),
    };
    let fit = fit(&write_session(folder.path(), 300.0, &[take]));
    relative("f1", estimate(&fit, 0, "glug.f1_hz"), 80.0, 0.02);
    relative("f2", estimate(&fit, 0, "glug.f2_hz"), 300.0, 0.02);
    relative("B1", estimate(&fit, 0, "glug.b1_per_s"), 45.0, 0.15);
    relative("B2", estimate(&fit, 0, "glug.b2_per_s"), 40.0, 0.15);
    close("c", estimate(&fit, 0, "viscosity_c"), 0.33, 0.02);
    close(
        "V0",
        estimate(&fit, 0, "amplitude.silent_below_ml"),
        84.333,
        5.0,
    );
    close("gain", estimate(&fit, 0, "output.gain_db"), -6.0206, 0.2);
    relative(
        "rate",
        estimate(&fit, 0, "outflow rate at 135° (ml/s)"),
        60.0,
        0.02,
    );
    relative("pour time", estimate(&fit, 0, "pour_time_s"), 5.0, 0.02);
    relative("pocket", estimate(&fit, 0, "bottle.pocket_ml"), 5.0, 0.1);
    // Every audible unit found (those above the noise gate), each onset within a millisecond.
    let units = &fit.recordings[0].units;
    let audible = rendered.onsets.iter().filter(|o| o.amplitude > 0.1).count();
    assert!(
        units.len() >= audible,
        "{} units fitted of {audible} clearly audible",
        units.len()
    );
    for unit in units {
        let nearest = rendered
            .onsets
            .iter()
            .map(|o| ((o.sample as f64 + o.fraction) / 25_000.0 - unit.fit.onset_s).abs())
            .fold(f64::MAX, f64::min);
        assert!(nearest < 0.001, "an onset {nearest} s from the engine's");
    }
    let model = Scene::parse(&fit.liquids[0].model_toml).expect("the model is a scene");
    relative("model's f1", model.config.frequency_hz[0], 80.0, 0.02);
    assert!(fit.liquids[0]
        .kept_default
        .iter()
        .any(|(key, _)| key == "curves.drain"));
}

/// Another bottle at 48 kHz, at two tilts with its own drain curve and an amplitude spread, noise
/// 30 dB down: f, B, c, the rates, V0, the spread and the curves come back.
#[test]
fn a_known_model_at_two_tilts_comes_back() {
    let model = "sample_rate = 48000\nseed = 11\nviscosity_c = 0.6\n\
        [glug]\nf1_hz = 110.0\nf2_hz = 420.0\nb1_per_s = 30.0\nb2_per_s = 60.0\n\
        [bottle]\npocket_ml = 7.0\n[amplitude]\nsilent_below_ml = 60.0\nspread = 0.2\n\
        [curves]\ndrain = [[0.0, 0.0], [90.0, 0.3], [100.0, 0.5], [135.0, 1.0], [180.0, 0.8]]\n";
    let steep = render(&format!("tilt_deg = 135.0\nduration_s = 7.0\n{model}"));
    let shallow = render(&format!("tilt_deg = 100.0\nduration_s = 11.0\n{model}"));
    let folder = tempfile::tempdir().unwrap();
    let fit = fit(&write_session(
        folder.path(),
        300.0,
        &[
            Take {
                name: "steep",
                rendered: &steep,
                tilt_deg: 135.0,
                liquid: None,
                weight: true,
                noise_db: Some(-30.0),
            },
            Take {
                name: "shallow",
                rendered: &shallow,
                tilt_deg: 100.0,
                liquid: None,
                weight: true,
                noise_db: Some(-30.0),
            },
        ],
    ));
    relative("f1", estimate(&fit, 0, "glug.f1_hz"), 110.0, 0.02);
    relative("f2", estimate(&fit, 0, "glug.f2_hz"), 420.0, 0.02);
    relative("B1", estimate(&fit, 0, "glug.b1_per_s"), 30.0, 0.15);
    relative("B2", estimate(&fit, 0, "glug.b2_per_s"), 60.0, 0.15);
    close("c", estimate(&fit, 0, "viscosity_c"), 0.6, 0.02);
    close(
        "V0",
        estimate(&fit, 0, "amplitude.silent_below_ml"),
        60.0,
        5.0,
    );
    close("spread", estimate(&fit, 0, "amplitude.spread"), 0.2, 0.06);
    relative(
        "rate at 135°",
        estimate(&fit, 0, "outflow rate at 135° (ml/s)"),
        60.0,
        0.02,
    );
    relative(
        "rate at 100°",
        estimate(&fit, 0, "outflow rate at 100° (ml/s)"),
        30.0,
        0.02,
    );
    relative("pocket", estimate(&fit, 0, "bottle.pocket_ml"), 7.0, 0.1);
    let model = Scene::parse(&fit.liquids[0].model_toml).expect("the model is a scene");
    let h = sake_glug_engine::Curve::Drain.of(&model.config.curves);
    close("h(100°)", h.at(100.0), 0.5, 0.01);
    let r = sake_glug_engine::Curve::Rest.of(&model.config.curves);
    // The default rest curve's 0.083 at 100° (25 ml of 300), 0 at 135°.
    close("r(100°)", r.at(100.0), 0.0833, 0.01);
    close("r(135°)", r.at(135.0), 0.0, 0.01);
}

/// Two liquids give two models, each its own c, written into the folder as <liquid>.toml.
#[test]
fn two_liquids_give_two_models() {
    let thin = render("sample_rate = 25000\ntilt_deg = 135.0\nseed = 2\nviscosity_c = 0.2\n");
    let thick = render("sample_rate = 25000\ntilt_deg = 135.0\nseed = 3\nviscosity_c = 0.7\n");
    let folder = tempfile::tempdir().unwrap();
    let fit = fit(&write_session(
        folder.path(),
        300.0,
        &[
            Take {
                name: "thin",
                rendered: &thin,
                tilt_deg: 135.0,
                liquid: Some("water"),
                weight: true,
                noise_db: None,
            },
            Take {
                name: "thick",
                rendered: &thick,
                tilt_deg: 135.0,
                liquid: Some("honey"),
                weight: true,
                noise_db: None,
            },
        ],
    ));
    let out_dir = folder.path().join("models");
    let (report, plot) = (folder.path().join("fit.md"), folder.path().join("fit.png"));
    let outputs = FitOutputs {
        out_dir: Some(out_dir.clone()),
        report: Some(report.clone()),
        plot: Some(plot.clone()),
        ..FitOutputs::default()
    };
    write_fit(&fit, &outputs).unwrap();
    let report = std::fs::read_to_string(report).unwrap();
    assert!(report.contains("## Liquid `honey`"), "{report}");
    assert!(std::fs::read(&plot).unwrap().starts_with(b"\x89PNG"));
    if let Ok(keep) = std::env::var("SAKE_GLUG_KEEP_FIT_PLOT") {
        std::fs::copy(&plot, keep).unwrap();
    }
    for (liquid, c) in [("water", 0.2), ("honey", 0.7)] {
        let scene = Scene::load(&out_dir.join(format!("{liquid}.toml"))).unwrap();
        close(liquid, scene.lanes.viscosity.value_at(0.0), c, 0.02);
    }
    let one_model = FitOutputs {
        model: Some(folder.path().join("m.toml")),
        ..FitOutputs::default()
    };
    let error = write_fit(&fit, &one_model).unwrap_err().to_string();
    assert!(error.contains("--out-dir"), "{error}");
}
