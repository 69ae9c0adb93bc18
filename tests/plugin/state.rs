//! State save and restore is byte-identical, and a restored plugin renders the same samples.

use nice_plug::prelude::Plugin;

use crate::host::TestHost;
use sake_glug::device::midi::MidiMap;

#[test]
fn save_restore_save_is_byte_identical_and_sounds_the_same() {
    let mut original = TestHost::new(48_000.0, 2);
    for (id, normalized) in [
        ("tilt", 0.77),
        ("visc", 0.123_456),
        ("fill", 0.9),
        ("pour", 0.313),
        ("gain", 0.71),
        ("f1", 0.4),
        ("f2", 0.61),
        ("b1", 0.2),
        ("b2", 0.9),
        ("pocket", 0.35),
        ("cap", 0.3),
        ("tjit", 0.5),
        ("fjit", 0.25),
        ("dsig", 0.66),
        ("seed", 0.000_123),
        ("drain", 1.0),
        ("ceil", 0.95),
    ] {
        original.set_normalized(id, normalized);
    }
    original.plugin.glug_params().set_midi_map(MidiMap {
        channel: Some(4),
        tilt_msb: Some(1),
        tilt_lsb: None,
        viscosity: Some(74),
        fill: None,
    });
    let saved = original.state();

    let mut restored = TestHost::new(48_000.0, 2);
    assert_ne!(restored.state(), saved, "the test must change the state");
    restored.restore(&original);
    assert_eq!(restored.state(), saved);
    assert_eq!(
        restored.plugin.glug_params().midi_map(),
        original.plugin.glug_params().midi_map()
    );

    // Saving the restored copy again gives the same bytes, and the same sound.
    let again = TestHost::new(48_000.0, 2);
    again.restore(&restored);
    assert_eq!(again.state(), saved);
    original.plugin.reset();
    restored.plugin.reset();
    assert_eq!(
        original.render_mono(48_000, 512),
        restored.render_mono(48_000, 4096)
    );
}
