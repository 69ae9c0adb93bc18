//! Every kind of file the product reads, named as a FIFO or as `/dev/zero`, is refused at once:
//! no reader waits for a FIFO's writer or reads a device without end. One row per way in: the
//! scene, a model file (`--model`, the editor's "Load model…", a study's stimulus), a MIDI take,
//! a CSV lane, a fit session, a recording and a weight log named by one, a study spec and a
//! stimulus's scene, and the study logs the analyses read.
//!
//! Each read runs on a thread of its own: a reader that waits turns into a failure here after a
//! minute, rather than a suite that never ends (the readers refuse in microseconds).

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use sake_glug_analysis::{
    analyze_constant_logs, analyze_paired_logs, DryRuns, PsychometricOptions,
};
use sake_glug_fit::{fit_session, FitSession};
use sake_glug_model_file::ModelFile;
use sake_glug_render::Scene;
use sake_glug_study::Spec;

/// A way the product reads a file: its name, and the read of `bad` (the file under test) with
/// the folder the other files it needs are in.
type Reader = fn(bad: &Path, folder: &Path) -> Result<(), String>;

fn readers() -> Vec<(&'static str, Reader)> {
    vec![
        ("scene", |bad, _| {
            Scene::load(bad).map(drop).map_err(|e| e.to_string())
        }),
        ("model file", |bad, _| {
            ModelFile::load(bad).map(drop).map_err(|e| e.to_string())
        }),
        ("MIDI take", |bad, _| {
            let text = format!("midi_take = {:?}\n", bad.display().to_string());
            Scene::parse(&text).map(drop).map_err(|e| e.to_string())
        }),
        ("CSV lane", |bad, _| {
            let text = format!(
                "tilt_deg = {{ csv = {:?}, column = \"tilt\" }}\n",
                bad.display().to_string()
            );
            Scene::parse(&text).map(drop).map_err(|e| e.to_string())
        }),
        ("fit session", |bad, _| {
            FitSession::load(bad).map(drop).map_err(|e| e.to_string())
        }),
        ("recording", |bad, folder| {
            let text = format!(
                "capacity_ml = 300.0\n[[recording]]\naudio = {:?}\ntilt_deg = 135.0\n\
                 start_ml = 300.0\n",
                bad.display().to_string()
            );
            fit(&text, folder)
        }),
        ("weight log", |bad, folder| {
            let text = format!(
                "capacity_ml = 300.0\n[[recording]]\naudio = \"pour.wav\"\ntilt_deg = 135.0\n\
                 weight = {{ csv = {:?}, time = \"t\", column = \"g\" }}\n",
                bad.display().to_string()
            );
            fit(&text, folder)
        }),
        ("study spec", |bad, _| {
            Spec::load(bad).map(drop).map_err(|e| e.to_string())
        }),
        ("a stimulus's scene", |bad, folder| {
            stimulus("scene", bad, folder)
        }),
        ("a stimulus's model file", |bad, folder| {
            stimulus("model", bad, folder)
        }),
        ("a set's manifest (--take-from)", |bad, _| {
            sake_glug_render::variations::read_take(bad, 1)
                .map(drop)
                .map_err(|e| e.to_string())
        }),
        ("paired study log", |bad, _| {
            analyze_paired_logs(&[bad], DryRuns::Refused)
                .map(drop)
                .map_err(|e| e.to_string())
        }),
        ("constant study log", |bad, _| {
            analyze_constant_logs(&[bad], &PsychometricOptions::default(), DryRuns::Refused)
                .map(drop)
                .map_err(|e| e.to_string())
        }),
    ]
}

fn fit(session: &str, folder: &Path) -> Result<(), String> {
    FitSession::parse(session, &folder.join("session.toml"))
        .and_then(|session| fit_session(&session))
        .map(drop)
        .map_err(|e| e.to_string())
}

fn stimulus(key: &str, bad: &Path, folder: &Path) -> Result<(), String> {
    let text = format!(
        "design = \"paired\"\nduration_s = 1.0\ngap_s = 0.5\nrepetitions = 1\nseed = 1\n\
         [stimuli.a]\n{key} = {:?}\n\
         [stimuli.b]\npreset = \"water\"\n",
        bad.display().to_string()
    );
    Spec::parse(&text, &folder.join("spec.toml"))
        .map(drop)
        .map_err(|e| e.to_string())
}

/// A named pipe at `path`.
fn make_fifo(path: &Path) {
    let name = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0, "mkfifo");
}

/// A second of a 200 Hz tone at 8 kHz, for the session whose weight log is under test.
fn write_recording(path: &Path) {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 8000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut writer = hound::WavWriter::create(path, spec).unwrap();
    for n in 0..8000 {
        let x = (2.0 * std::f64::consts::PI * 200.0 * n as f64 / 8000.0).sin();
        writer.write_sample((x * 10_000.0) as i16).unwrap();
    }
    writer.finalize().unwrap();
}

/// `reader`'s verdict on `bad`, or a failure once it has waited a minute.
fn read_on_a_thread(reader: Reader, bad: PathBuf, folder: PathBuf) -> Result<(), String> {
    let (sender, receiver) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = sender.send(reader(&bad, &folder));
    });
    receiver
        .recv_timeout(Duration::from_secs(60))
        .unwrap_or_else(|_| panic!("the read still waits after a minute"))
}

#[test]
fn every_input_refuses_a_fifo_and_a_device_at_once() {
    let folder = tempfile::tempdir().unwrap();
    let fifo = folder.path().join("pipe");
    make_fifo(&fifo);
    write_recording(&folder.path().join("pour.wav"));
    let mut wrong = Vec::new();
    for (name, reader) in readers() {
        for (bad, what) in [
            (fifo.clone(), "a FIFO (named pipe)"),
            (PathBuf::from("/dev/zero"), "a device"),
        ] {
            let verdict = read_on_a_thread(reader, bad.clone(), folder.path().to_owned());
            match verdict {
                Err(message) if message.contains(&format!("it is {what}, not a regular file")) => {}
                other => wrong.push(format!("{name} from {}: {other:?}", bad.display())),
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
