//! The app's own options, taken out of the command line before nice-plug's wrapper parses the
//! rest (it refuses options it does not know).

use std::net::IpAddr;
use std::path::PathBuf;

use clap::{CommandFactory, Parser};
use sake_glug_device::midi::MidiSetting;
use sake_glug_device::Axis;
use sake_glug_plugin::{DEFAULT_AXIS, DEFAULT_OSC_INTERFACE};

/// Sake Glug's own options of the standalone app (the wrapper's follow).
#[derive(Debug, Parser)]
#[command(name = "sake-glug-standalone", version, disable_help_flag = true)]
pub struct AppArgs {
    /// Listen for OSC on this UDP port: /sakeglug/tilt, /viscosity, /fill, /refill, and the
    /// gravity vectors of GyrOSC, TouchOSC and Sensors2OSC.
    #[arg(long, value_name = "PORT", value_parser = clap::value_parser!(u16).range(1..))]
    pub osc_port: Option<u16>,
    /// The address OSC listens on: 127.0.0.1 takes packets from this computer only; 0.0.0.0
    /// (or a network interface's own address) takes them from the network, from a phone.
    #[arg(long, value_name = "ADDRESS", default_value_t = DEFAULT_OSC_INTERFACE)]
    pub osc_bind: IpAddr,
    /// The phone's or sensor's axis that points from the bottle's base to its mouth, for
    /// gravity vectors: +x, -x, +y, -y, +z or -z.
    #[arg(long, value_name = "AXIS", default_value_t = DEFAULT_AXIS)]
    pub osc_axis: Axis,
    /// No editor window (no display needed); quit with Ctrl-C or SIGTERM.
    #[arg(long)]
    pub no_editor: bool,
    /// A model file (as `sake-glug fit` writes) to play: its bottle and liquid, loaded as the
    /// editor's "Load model…" loads it.
    #[arg(long, value_name = "MODEL.toml")]
    pub model: Option<PathBuf>,
    /// An actuator to compensate for (MODEL.md §18): a shipped profile's name or a profile
    /// file's path, as the editor's Actuator menu or "Load profile…" sets it.
    #[arg(long, value_name = "NAME|PROFILE.toml")]
    pub actuator: Option<String>,
    /// With --actuator: equalises the level over the skin's threshold (the editor's "felt").
    #[arg(long, requires = "actuator")]
    pub felt: bool,
    /// MIDI learn without the editor: the first CC the device sends is taken for this row of
    /// the MIDI settings (tilt, tilt_lsb, viscosity or fill), with its channel, as the MIDI
    /// panel's "Learn" button takes it; the app prints what it took.
    #[arg(long, value_name = "ROW", value_parser = parse_learn_row)]
    pub learn: Option<MidiSetting>,
}

/// A row of the MIDI settings by its name: its saved key without `midi_cc_`.
fn learn_row_name(setting: MidiSetting) -> Option<&'static str> {
    setting.key().strip_prefix("midi_cc_")
}

fn parse_learn_row(name: &str) -> Result<MidiSetting, String> {
    MidiSetting::all()
        .find(|&setting| learn_row_name(setting) == Some(name))
        .ok_or_else(|| {
            let rows: Vec<&str> = MidiSetting::all().filter_map(learn_row_name).collect();
            format!(
                "{name:?} is not a row of the MIDI settings: {}",
                rows.join(", ")
            )
        })
}

/// Our options and whether each takes a value.
const OWN: [(&str, bool); 8] = [
    ("--osc-port", true),
    ("--osc-bind", true),
    ("--osc-axis", true),
    ("--no-editor", false),
    ("--model", true),
    ("--actuator", true),
    ("--felt", false),
    ("--learn", true),
];

/// Splits the command line into our options (as `--name=value`, after the program name) and
/// the wrapper's (with the program name first).
pub fn split(args: impl IntoIterator<Item = String>) -> (Vec<String>, Vec<String>) {
    let mut args = args.into_iter();
    let program = args.next().unwrap_or_else(|| "sake-glug-standalone".into());
    let mut own = vec![program.clone()];
    let mut rest = vec![program];
    while let Some(arg) = args.next() {
        let (name, inline_value) = match arg.split_once('=') {
            Some((name, value)) => (name.to_owned(), Some(value.to_owned())),
            None => (arg.clone(), None),
        };
        match OWN.iter().find(|(known, _)| *known == name) {
            // `--osc-axis -z`: the value may start with a dash, so it is joined with `=`.
            Some((_, true)) => match inline_value.or_else(|| args.next()) {
                Some(value) => own.push(format!("{name}={value}")),
                None => own.push(name),
            },
            Some((_, false)) => own.push(arg),
            None => rest.push(arg),
        }
    }
    (own, rest)
}

/// Parses what [`split`] took out.
pub fn parse(own: &[String]) -> Result<AppArgs, clap::Error> {
    AppArgs::try_parse_from(own)
}

/// Our options' help, printed before the wrapper's.
pub fn help() -> String {
    AppArgs::command()
        .about("Sake Glug without a DAW. Sake Glug's options:")
        .render_help()
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strings(args: &[&str]) -> Vec<String> {
        args.iter().map(|arg| arg.to_string()).collect()
    }

    #[test]
    fn our_options_are_taken_out_and_the_rest_passed_on() {
        let (own, rest) = split(strings(&[
            "app",
            "--backend",
            "jack",
            "--osc-port",
            "9000",
            "--osc-axis",
            "-z",
            "--osc-bind",
            "0.0.0.0",
            "--no-editor",
            "--connect-jack-midi-input=a:b",
        ]));
        assert_eq!(
            own,
            strings(&[
                "app",
                "--osc-port=9000",
                "--osc-axis=-z",
                "--osc-bind=0.0.0.0",
                "--no-editor"
            ])
        );
        assert_eq!(
            rest,
            strings(&["app", "--backend", "jack", "--connect-jack-midi-input=a:b"])
        );
        let parsed = parse(&own).unwrap();
        assert_eq!(parsed.osc_port, Some(9000));
        assert_eq!(parsed.osc_axis, Axis::MinusZ);
        assert_eq!(parsed.osc_bind, IpAddr::from([0, 0, 0, 0]));
        assert!(parsed.no_editor);
    }

    #[test]
    fn the_model_file_is_taken_out_with_its_path() {
        for args in [
            &["app", "--model", "honey.toml", "--backend", "dummy"][..],
            &["app", "--model=honey.toml", "--backend", "dummy"][..],
        ] {
            let (own, rest) = split(strings(args));
            assert_eq!(own, strings(&["app", "--model=honey.toml"]));
            assert_eq!(rest, strings(&["app", "--backend", "dummy"]));
            let parsed = parse(&own).unwrap();
            assert_eq!(parsed.model, Some(PathBuf::from("honey.toml")));
        }
        assert_eq!(parse(&strings(&["app"])).unwrap().model, None);
        let (own, _) = split(strings(&["app", "--model"]));
        let error = parse(&own).unwrap_err().to_string();
        assert!(error.contains("--model"), "{error}");
    }

    #[test]
    fn the_actuator_and_felt_are_taken_out() {
        let (own, rest) = split(strings(&[
            "app",
            "--actuator",
            "my shaker.toml",
            "--felt",
            "--backend",
            "jack",
        ]));
        assert_eq!(
            own,
            strings(&["app", "--actuator=my shaker.toml", "--felt"])
        );
        assert_eq!(rest, strings(&["app", "--backend", "jack"]));
        let parsed = parse(&own).unwrap();
        assert_eq!(parsed.actuator.as_deref(), Some("my shaker.toml"));
        assert!(parsed.felt);
        // --felt alone means nothing.
        let error = parse(&strings(&["app", "--felt"])).unwrap_err().to_string();
        assert!(error.contains("--actuator"), "{error}");
    }

    #[test]
    fn the_learn_row_is_taken_out_by_its_name() {
        use sake_glug_engine::Control;
        let (own, rest) = split(strings(&["app", "--learn", "tilt", "--backend", "jack"]));
        assert_eq!(own, strings(&["app", "--learn=tilt"]));
        assert_eq!(rest, strings(&["app", "--backend", "jack"]));
        assert_eq!(
            parse(&own).unwrap().learn,
            Some(MidiSetting::Cc(Control::Tilt))
        );
        let lsb = parse(&strings(&["app", "--learn=tilt_lsb"])).unwrap();
        assert_eq!(lsb.learn, Some(MidiSetting::TiltLsb));
        let error = parse(&strings(&["app", "--learn=channel"]))
            .unwrap_err()
            .to_string();
        assert!(error.contains("tilt, tilt_lsb, viscosity, fill"), "{error}");
    }

    #[test]
    fn bad_values_are_refused_by_name() {
        for (args, fault) in [
            (&["app", "--osc-port=0"][..], "--osc-port"),
            (&["app", "--osc-port", "http"][..], "--osc-port"),
            (&["app", "--osc-axis=w"][..], "\"w\" is not an axis"),
            (&["app", "--osc-port"][..], "--osc-port"),
            (&["app", "--osc-bind=everywhere"][..], "--osc-bind"),
        ] {
            let (own, _) = split(strings(args));
            let error = parse(&own).unwrap_err().to_string();
            assert!(error.contains(fault), "{args:?}: {error}");
        }
        let defaults = parse(&strings(&["app"])).unwrap();
        assert_eq!((defaults.osc_port, defaults.osc_axis), (None, DEFAULT_AXIS));
        assert!(
            defaults.osc_bind.is_loopback(),
            "this computer only, unless asked"
        );
    }
}
