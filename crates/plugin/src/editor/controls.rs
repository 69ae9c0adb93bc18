//! A slider for every parameter of the main group, and the model group folded away below.

use nice_plug::prelude::*;
use nice_plug_egui::widgets::ParamSlider;

use std::sync::atomic::Ordering::Relaxed;

use crate::feed::Feed;
use crate::params::GlugParams;
use sake_glug_engine::Control;

/// The main group's sliders.
const MAIN_SLIDER_WIDTH: f32 = 170.0;
/// The model group's: narrower, as its names are longer and the group is indented, so that its
/// rows fit the column as the main group's do.
const MODEL_SLIDER_WIDTH: f32 = 110.0;

pub fn show(ui: &mut egui::Ui, params: &GlugParams, feed: &Feed, setter: &ParamSetter) {
    egui::Grid::new("main_group")
        .num_columns(3)
        .spacing([8.0, 6.0])
        .show(ui, |ui| {
            for &control in Control::ALL {
                let param = &params.controls[control];
                ui.label(param.name());
                ui.add(ParamSlider::for_param(param, setter).with_width(MAIN_SLIDER_WIDTH));
                // A device (MIDI or OSC) that drives the control plays its own value: shown
                // beside the parameter, which it does not move.
                let played = feed.played[control].load(Relaxed);
                if (played - param.value()).abs() > displayed_step(control) {
                    ui.label(
                        egui::RichText::new(format!(
                            "device: {}",
                            param
                                .normalized_value_to_string(param.preview_normalized(played), true)
                        ))
                        .small()
                        .weak(),
                    );
                } else {
                    ui.label("");
                }
                ui.end_row();
            }
        });
    egui::CollapsingHeader::new("Model").show(ui, |ui| {
        let model = &params.model;
        egui::Grid::new("model_group")
            .num_columns(2)
            .spacing([8.0, 4.0])
            .show(ui, |ui| {
                for param in model.constants.iter().chain([&model.ceiling]) {
                    row(ui, param, setter, MODEL_SLIDER_WIDTH);
                }
                row(ui, &model.seed, setter, MODEL_SLIDER_WIDTH);
                row(ui, &model.drain, setter, MODEL_SLIDER_WIDTH);
            });
    });
}

fn row<P: Param>(ui: &mut egui::Ui, param: &P, setter: &ParamSetter, width: f32) {
    ui.label(param.name());
    ui.add(ParamSlider::for_param(param, setter).with_width(width));
    ui.end_row();
}

/// Half the control's knob step: values closer than that show the same.
fn displayed_step(control: Control) -> f32 {
    (control.quantity().knob.step() as f32).max(1e-4) / 2.0
}
