//! The output layouts a host can choose: stereo (the default) and mono, both carrying the same
//! signal (MODEL.md §6). Chosen here as a CLAP host does, through `clap.audio-ports-config`
//! before activation. (pedalboard cannot ask a generator for mono: docs/guide/sound-designer.md, "Mono or stereo".)

use crate::clap_host::ClapInstance;

fn pour(channels: u32) -> Vec<f32> {
    let mut instance = ClapInstance::new();
    assert!(
        instance.select_output_channels(channels),
        "no {channels}-channel layout"
    );
    instance.set_text("Tilt", "135");
    instance.set_text("Seed", "3");
    instance.activate(48_000.0);
    instance.render(48_000, 512)
}

#[test]
fn a_host_can_choose_stereo_or_mono() {
    let channels: Vec<u32> = ClapInstance::new()
        .audio_ports_configs()
        .iter()
        .map(|(_, channels)| *channels)
        .collect();
    assert_eq!(channels, [2, 1]);
}

#[test]
fn the_mono_layout_carries_the_stereo_layouts_signal() {
    let stereo = pour(2);
    assert!(stereo.iter().any(|y| y.abs() > 0.01));
    assert_eq!(pour(1), stereo);
}
