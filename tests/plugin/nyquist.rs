//! At every sample rate from 1 kHz to 768 kHz: a component at or above Nyquist is omitted, and
//! whatever the parameters, the output is finite, within the ceiling and free of denormals.
//!
//! Where the f2 knob (10 Hz – 24 kHz) reaches Nyquist the plugin is driven through its
//! parameters; at 88.2 kHz and above it cannot, so the same settings with f2 past the knob go
//! through the plugin's real-time side, the code `process()` runs after reading the parameters.

use nice_plug::prelude::Plugin;

use crate::host::{peak, TestHost};
use sake_glug_plugin::{Feed, RealtimeEngine, Settings};

const RATES: [f32; 10] = [
    1_000.0, 8_000.0, 22_050.0, 44_100.0, 48_000.0, 88_200.0, 96_000.0, 192_000.0, 384_000.0,
    768_000.0,
];

/// A host pouring at full speed with only the f2 component (c = 0) at `f2_hz`, no frequency spread.
fn f2_only(rate: f32, f2_hz: f64) -> TestHost {
    let host = TestHost::new(rate, 1);
    host.set_text("tilt", "135");
    host.set_text("visc", "0");
    host.set_text("fjit", "0");
    host.set_text("f2", &format!("{f2_hz:.1}"));
    host
}

fn quarter_second(host: &mut TestHost) -> Vec<f32> {
    host.plugin.reset();
    let total = (host.sample_rate / 4.0) as usize;
    host.render_mono(total, 512)
}

/// The f2 knob stops at 24 kHz: at 88.2 kHz and above it cannot reach Nyquist.
const F2_KNOB_MAX_HZ: f64 = 24_000.0;

/// A quarter second of the same pour through the plugin's real-time side ([`RealtimeEngine`],
/// what `process()` runs once nice-plug has read the parameters) with f2 at `f2_hz`, which may
/// lie beyond the knob's reach; and the components sounding at its end.
fn quarter_second_beyond_the_knob(rate: f32, f2_hz: f64) -> (Vec<f32>, usize) {
    let host = f2_only(rate, 1_000.0);
    let mut settings = Settings::from_params(host.plugin.glug_params());
    settings.config.frequency_hz[1] = f2_hz;
    let mut engine = RealtimeEngine::new(rate as f64, settings.config);
    let feed = Feed::default();
    let mut out = vec![0.0f32; (rate / 4.0) as usize];
    for block in out.chunks_mut(512) {
        engine.process(&settings, block, &feed);
    }
    (out, engine.engine().sounding_components())
}

#[test]
fn a_component_at_or_above_nyquist_is_omitted() {
    for rate in RATES {
        let nyquist = rate as f64 / 2.0;
        // Below Nyquist the component sounds, through the knob where it reaches and beyond it.
        let below = nyquist * 0.9;
        if below <= F2_KNOB_MAX_HZ {
            let mut host = f2_only(rate, below);
            assert!(
                peak(&quarter_second(&mut host)) > 1e-3,
                "{below} Hz at {rate} Hz must sound"
            );
        }
        let (out, _) = quarter_second_beyond_the_knob(rate, below);
        assert!(peak(&out) > 1e-3, "{below} Hz at {rate} Hz must sound");
        // At and above Nyquist it is omitted at every rate: silence, and nothing computed.
        for f2 in [nyquist, nyquist * 1.5, nyquist * 4.0] {
            if f2 <= F2_KNOB_MAX_HZ {
                let mut host = f2_only(rate, f2);
                let out = quarter_second(&mut host);
                assert!(
                    out.iter().all(|&s| s == 0.0),
                    "{f2} Hz at {rate} Hz must be omitted, peak {}",
                    peak(&out)
                );
            }
            let (out, sounding) = quarter_second_beyond_the_knob(rate, f2);
            assert!(
                out.iter().all(|&s| s == 0.0) && sounding == 0,
                "{f2} Hz at {rate} Hz must be omitted: peak {}, {sounding} sounding",
                peak(&out)
            );
        }
    }
}

#[test]
fn output_is_finite_bounded_and_normal_at_every_rate_and_extreme() {
    let extremes: [[(&str, f32); 8]; 3] = [
        [
            ("tilt", 0.75),
            ("gain", 1.0),
            ("pocket", 0.0),
            ("pour", 0.0),
            ("b1", 0.0),
            ("b2", 0.0),
            ("f1", 0.0),
            ("ceil", 1.0),
        ],
        [
            ("tilt", 1.0),
            ("gain", 0.0),
            ("pocket", 1.0),
            ("pour", 1.0),
            ("b1", 1.0),
            ("b2", 1.0),
            ("f1", 1.0),
            ("ceil", 0.0),
        ],
        [
            ("tilt", 0.6),
            ("gain", 1.0),
            ("cap", 1.0),
            ("dsig", 1.0),
            ("fjit", 1.0),
            ("tjit", 1.0),
            ("drain", 1.0),
            ("ceil", 0.5),
        ],
    ];
    for rate in RATES {
        for set in &extremes {
            let mut host = TestHost::new(rate, 2);
            for &(id, normalized) in set {
                host.set_normalized(id, normalized);
            }
            let ceiling = host.plugin.glug_params().model_config().ceiling as f32;
            host.plugin.reset();
            let total = ((rate / 2.0) as usize).max(2048);
            let out = host.render_mono(total, 1024);
            for &sample in &out {
                assert!(sample.is_finite(), "{rate} Hz: {sample}");
                assert!(
                    sample.abs() <= ceiling,
                    "{rate} Hz: {sample} over {ceiling}"
                );
                assert!(
                    sample == 0.0 || sample.is_normal(),
                    "{rate} Hz: denormal {sample:e}"
                );
            }
        }
    }
}
