//! "Actuator": the device the output drives (MODEL.md §18), one of the shipped profiles or none,
//! and the felt flag; or a profile of one's own (`sake-glug measure-actuator` writes one), its
//! path typed and loaded with "Load profile…", or come with a saved state, shown by name.

use nice_plug::context::gui::GuiContext;

use super::PathField;
use crate::actuator_setting::Actuator;
use crate::params::GlugParams;
use sake_glug_actuator::shipped_names;

/// What the menu shows without an actuator.
const NONE: &str = "none";

/// Shows the menu of the shipped profiles and "none", the felt flag, and the path field of a
/// profile of one's own; a change is saved in the state and told to the host.
pub fn show(
    ui: &mut egui::Ui,
    params: &GlugParams,
    gui: Option<&GuiContext>,
    field: &mut PathField,
) {
    let chosen = params.actuator.get();
    let shown = match &chosen {
        None => NONE.to_owned(),
        Some(actuator) if actuator.shipped => actuator.profile.name().to_owned(),
        Some(actuator) => format!("{} (own profile)", actuator.profile.name()),
    };
    let felt = chosen.as_ref().is_some_and(|actuator| actuator.felt);
    let mut changed = None;
    ui.horizontal(|ui| {
        ui.label(egui::RichText::new("Actuator").strong());
        egui::ComboBox::from_id_salt("actuator")
            .selected_text(&shown)
            .show_ui(ui, |ui| {
                if ui.selectable_label(chosen.is_none(), NONE).clicked() {
                    changed = Some(None);
                }
                for name in shipped_names() {
                    if ui.selectable_label(shown == name, name).clicked() {
                        changed = Some(Actuator::shipped(name, felt));
                    }
                }
            });
        let mut felt_now = felt;
        let checkbox = egui::Checkbox::new(&mut felt_now, "felt");
        if ui
            .add_enabled(chosen.is_some(), checkbox)
            .on_hover_text("Equalise over the skin's threshold instead of the acceleration")
            .changed()
        {
            changed = Some(chosen.clone().map(|actuator| Actuator {
                felt: felt_now,
                ..actuator
            }));
        }
    });
    ui.horizontal(|ui| {
        field.text_edit(ui, "/path/to/profile.toml");
        if ui.button("Load profile…").clicked() {
            match Actuator::find(field.path.trim(), felt) {
                Ok(actuator) => {
                    field.refused = None;
                    changed = Some(Some(actuator));
                }
                Err(error) => field.refused = Some(error.to_string()),
            }
        }
    });
    field.show_refusal(ui);
    if let Some(actuator) = changed {
        params.actuator.set(actuator);
        if let Some(gui) = gui {
            super::midi_settings::tell_host(gui);
        }
    }
}
