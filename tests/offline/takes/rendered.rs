//! Takes rendered offline as the model says for their lanes: a CSV column, an accelerometer's
//! gravity vector and a MIDI take give the same samples as the inline automation they stand
//! for; a malformed take is refused with its file, line and column, and nothing is written.

use crate::command::sake_glug;
use sake_glug_render::{render_scene_to_vec, Scene, SceneError};

fn render(scene: &Scene) -> Vec<f32> {
    render_scene_to_vec(scene).unwrap().0
}

/// Tilt rising from 80° to 140° over 0.6 s, and viscosity falling, as rows every 50 ms.
fn rows() -> Vec<(f64, f64, f64)> {
    (0..=20)
        .map(|k| {
            let t = k as f64 * 0.05;
            (t, (80.0 + 100.0 * t).min(140.0), 0.6 - 0.3 * t)
        })
        .collect()
}

#[test]
fn a_csv_column_renders_as_its_points() {
    let directory = tempfile::tempdir().unwrap();
    let mut csv = String::from("time_s,tilt_deg,visc\n");
    let mut tilt = Vec::new();
    let mut visc = Vec::new();
    for (t, theta, c) in rows() {
        csv += &format!("{t},{theta},{c}\n");
        tilt.push(format!("[{t}, {theta}]"));
        visc.push(format!("[{t}, {c}]"));
    }
    std::fs::write(directory.path().join("take.csv"), csv).unwrap();
    let from_csv = Scene::parse_in(
        "duration_s = 3.0\n\
         tilt_deg = { csv = \"take.csv\", column = \"tilt_deg\" }\n\
         viscosity_c = { csv = \"take.csv\", column = \"visc\" }\n",
        directory.path(),
    )
    .unwrap();
    let inline = Scene::parse(&format!(
        "duration_s = 3.0\ntilt_deg = [{}]\nviscosity_c = [{}]\n",
        tilt.join(", "),
        visc.join(", ")
    ))
    .unwrap();
    let samples = render(&from_csv);
    assert!(samples.iter().any(|y| y.abs() > 0.05), "the take pours");
    assert_eq!(samples, render(&inline));
}

#[test]
fn an_accelerometer_take_renders_as_the_tilt_of_its_gravity_vector() {
    let directory = tempfile::tempdir().unwrap();
    // The sensor's −y axis runs from base to mouth; at rest it reads +1 g along −y.
    let mut csv = String::from("time_s,ax,ay,az\n");
    let mut tilt = Vec::new();
    for (t, theta, _) in rows() {
        let radians = theta.to_radians();
        let (ay, az) = (-radians.cos(), radians.sin());
        csv += &format!("{t},0.0,{ay},{az}\n");
        // acos(a·u / |a|) with u = −y, as the contract of the CSV lane says.
        let reading = [0.0f64, ay, az];
        let norm = reading.iter().map(|x| x * x).sum::<f64>().sqrt();
        tilt.push(format!(
            "[{t}, {}]",
            (-ay / norm).clamp(-1.0, 1.0).acos().to_degrees()
        ));
    }
    std::fs::write(directory.path().join("phone.csv"), csv).unwrap();
    let from_csv = Scene::parse_in(
        "duration_s = 3.0\n\
         tilt_deg = { csv = \"phone.csv\", accel = [\"ax\", \"ay\", \"az\"], axis = \"-y\" }\n",
        directory.path(),
    )
    .unwrap();
    let inline = Scene::parse(&format!(
        "duration_s = 3.0\ntilt_deg = [{}]\n",
        tilt.join(", ")
    ))
    .unwrap();
    let samples = render(&from_csv);
    assert!(samples.iter().any(|y| y.abs() > 0.05), "the take pours");
    assert_eq!(samples, render(&inline));
}

#[test]
fn a_malformed_csv_take_is_refused_with_file_line_and_column() {
    let directory = tempfile::tempdir().unwrap();
    std::fs::write(
        directory.path().join("take.csv"),
        "time_s,tilt_deg\n0.0,90\n0.1,ninety\n",
    )
    .unwrap();
    let error = Scene::parse_in(
        "tilt_deg = { csv = \"take.csv\", column = \"tilt_deg\" }\n",
        directory.path(),
    )
    .unwrap_err();
    assert!(matches!(error, SceneError::Csv { .. }), "{error}");
    let message = error.to_string();
    for part in ["tilt_deg", "take.csv", "line 3", "\"ninety\""] {
        assert!(message.contains(part), "{message} lacks {part}");
    }
}

#[test]
fn the_command_line_renders_a_midi_take_and_refuses_a_broken_one() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    // Format 0, 480 ticks a quarter at 120 bpm: tilt to 135° (CC 16 = 96, CC 48 = 0) at once,
    // upright again after 3 s (2880 ticks).
    let track: &[u8] = &[
        0x00, 0xB0, 16, 96, 0x00, 0xB0, 48, 0, 0x96, 0x40, 0xB0, 16, 0, 0x00, 0xFF, 0x2F, 0x00,
    ];
    let mut file = b"MThd\0\0\0\x06\0\0\0\x01\x01\xE0MTrk".to_vec();
    file.extend((track.len() as u32).to_be_bytes());
    file.extend(track);
    std::fs::write(dir.join("take.mid"), &file).unwrap();
    std::fs::write(dir.join("quiet.toml"), "duration_s = 4.0\n").unwrap();
    let output = sake_glug(
        dir,
        &["render", "quiet.toml", "--midi", "take.mid", "-o", "t.wav"],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let summary = String::from_utf8_lossy(&output.stdout);
    assert!(
        !summary.contains(" 0 glug units"),
        "the take tilts the bottle: {summary}"
    );

    std::fs::write(dir.join("broken.mid"), &file[..20]).unwrap();
    let output = sake_glug(
        dir,
        &[
            "render",
            "quiet.toml",
            "--midi",
            "broken.mid",
            "-o",
            "b.wav",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("broken.mid"), "{stderr}");
    assert!(!dir.join("b.wav").exists(), "nothing is written");
}
