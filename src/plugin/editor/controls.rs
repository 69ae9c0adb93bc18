//! A slider for every parameter of the main group, and the model group folded away below.

use nice_plug::prelude::*;
use nice_plug_egui::widgets::ParamSlider;

use crate::plugin::params::GlugParams;

pub fn show(ui: &mut egui::Ui, params: &GlugParams, setter: &ParamSetter) {
    egui::Grid::new("main_group")
        .num_columns(2)
        .spacing([8.0, 6.0])
        .show(ui, |ui| {
            row(ui, &params.tilt, setter);
            row(ui, &params.viscosity, setter);
            row(ui, &params.fill, setter);
            row(ui, &params.pour_time, setter);
            row(ui, &params.gain, setter);
        });
    egui::CollapsingHeader::new("Model").show(ui, |ui| {
        let model = &params.model;
        egui::Grid::new("model_group")
            .num_columns(2)
            .spacing([8.0, 4.0])
            .show(ui, |ui| {
                for param in [
                    &model.f1,
                    &model.f2,
                    &model.b1,
                    &model.b2,
                    &model.pocket,
                    &model.capacity,
                ] {
                    row(ui, param, setter);
                }
                for param in [
                    &model.timing_jitter,
                    &model.freq_jitter,
                    &model.decay_sigma,
                    &model.ceiling,
                ] {
                    row(ui, param, setter);
                }
                row(ui, &model.seed, setter);
                row(ui, &model.drain, setter);
            });
    });
}

fn row<P: Param>(ui: &mut egui::Ui, param: &P, setter: &ParamSetter) {
    ui.label(param.name());
    ui.add(ParamSlider::for_param(param, setter).with_width(170.0));
    ui.end_row();
}
