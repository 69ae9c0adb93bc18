//! A slider for every parameter of the main group.

use nice_plug::prelude::*;
use nice_plug_egui::widgets::ParamSlider;

use crate::params::GlugParams;

pub fn show(ui: &mut egui::Ui, params: &GlugParams, setter: &ParamSetter) {
    egui::Grid::new("main_group").num_columns(2).spacing([8.0, 6.0]).show(ui, |ui| {
        row(ui, &params.tilt, setter);
        row(ui, &params.viscosity, setter);
        row(ui, &params.fill, setter);
        row(ui, &params.pour_time, setter);
        row(ui, &params.gain, setter);
    });
}

fn row(ui: &mut egui::Ui, param: &FloatParam, setter: &ParamSetter) {
    ui.label(param.name());
    ui.add(ParamSlider::for_param(param, setter).with_width(170.0));
    ui.end_row();
}
