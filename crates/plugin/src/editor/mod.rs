//! The egui editor: the main group's controls, the bottle at its tilt with its residual volume,
//! a scope of the output and the last units' envelopes. One concept per file.

mod actuator;
mod bottle;
mod controls;
mod envelopes;
mod midi_settings;
mod model_file;
mod osc_settings;
mod presets;
mod scope;

use std::sync::Arc;

use nice_plug::context::gui::GuiContext;
use nice_plug::editor::dpi::LogicalSize;
use nice_plug::prelude::PluginApi;
use nice_plug_egui::{
    create_egui_editor, EguiEditor, EguiEditorState, EguiNiceSettings, NiceEguiApp,
};

use crate::feed::Feed;
use crate::osc_input::OscInput;
use crate::params::GlugParams;

pub const WIDTH: f64 = 800.0;
pub const HEIGHT: f64 = 750.0;

/// The space between the window's edges and the content.
const MARGIN: f32 = 8.0;
/// The column of controls, MIDI and OSC settings: as wide as a slider row and what a device
/// plays beside it.
const CONTROLS_WIDTH: f32 = 370.0;
/// The scope's and the envelopes' height.
const PANEL_HEIGHT: f32 = 200.0;
/// What `ui.separator()` takes (its default spacing).
const SEPARATOR_HEIGHT: f32 = 6.0;

pub struct GlugEditor {
    params: Arc<GlugParams>,
    feed: Arc<Feed>,
    osc: Arc<OscInput>,
    gui: Option<GuiContext>,
    /// The preset last picked in the menu (its label).
    preset: usize,
    /// The MIDI settings were edited and the host is not told yet (it is, once the mouse is
    /// let go, not at every step of a drag).
    midi_edited: bool,
    /// The MIDI panel's learn in progress.
    midi_panel: midi_settings::MidiPanel,
    /// The model file's path field and the last refusal.
    model_field: PathField,
    /// The actuator profile's path field and the last refusal.
    actuator_field: PathField,
}

/// A file's path, typed or pasted (a file dialog would need GTK's development files or a
/// desktop portal's D-Bus stack: see docs/guide/sound-designer.md), and why its last load was refused.
#[derive(Debug, Default)]
pub struct PathField {
    /// The path as typed.
    pub path: String,
    /// Why the last load was refused, until the next load or clear.
    pub refused: Option<String>,
}

impl PathField {
    /// The text field, `hint` shown while it is empty.
    pub fn text_edit(&mut self, ui: &mut egui::Ui, hint: &str) {
        ui.add(
            egui::TextEdit::singleline(&mut self.path)
                .hint_text(hint)
                .desired_width(170.0),
        );
    }

    /// Why the last load was refused, in the error colour, if it was.
    pub fn show_refusal(&self, ui: &mut egui::Ui) {
        if let Some(reason) = &self.refused {
            ui.colored_label(ui.visuals().error_fg_color, reason);
        }
    }
}

pub fn create(
    params: Arc<GlugParams>,
    feed: Arc<Feed>,
    osc: Arc<OscInput>,
) -> Option<EguiEditor<GlugEditor>> {
    // The audio thread asks for redraws through the feed, when what it shows changes; so does a
    // quit signal in the standalone app, so that the window closes at once.
    let repaint = feed.repaint.clone();
    crate::standalone::wake_editor_with({
        let repaint = repaint.clone();
        move || repaint.request_repaint()
    });
    let app = GlugEditor {
        params,
        feed,
        osc,
        gui: None,
        preset: 0,
        midi_edited: false,
        midi_panel: midi_settings::MidiPanel::default(),
        model_field: PathField::default(),
        actuator_field: PathField::default(),
    };
    create_egui_editor(
        EguiEditorState::from_size(LogicalSize::new(WIDTH, HEIGHT), 1.0),
        repaint,
        EguiNiceSettings::new().with_tile("Sake Glug"),
        app,
    )
}

impl NiceEguiApp for GlugEditor {
    fn build(
        &mut self,
        _egui_ctx: egui::Context,
        nice_gui_ctx: GuiContext,
        _frame: &mut nice_plug_egui::Frame,
    ) -> Result<(), nice_plug_egui::baseview::HandlerError> {
        self.gui = Some(nice_gui_ctx);
        Ok(())
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut nice_plug_egui::Frame) {
        // The standalone app got SIGINT, SIGTERM or SIGHUP: closing the window ends it cleanly.
        if crate::standalone::quit_requested() {
            ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
        }
        let Some(gui) = &self.gui else {
            return;
        };
        let setter = gui.param_setter();
        // The root Ui is the whole window, edge to edge: keep the content off the edges.
        egui::Frame::new().inner_margin(MARGIN).show(ui, |ui| {
            ui.heading("Sake Glug");
            // Unfolding the model group makes the controls taller than the window: they
            // scroll, so the scope and envelopes below stay in view.
            let controls_height = ui.available_height()
                - PANEL_HEIGHT
                - 2.0 * ui.spacing().item_spacing.y
                - SEPARATOR_HEIGHT;
            ui.horizontal_top(|ui| {
                ui.vertical(|ui| {
                    ui.set_width(CONTROLS_WIDTH);
                    egui::ScrollArea::vertical()
                        .max_height(controls_height)
                        .show(ui, |ui| {
                            presets::show(ui, &self.params, &setter, &mut self.preset);
                            model_file::show(ui, &self.params, gui, &mut self.model_field);
                            actuator::show(ui, &self.params, Some(gui), &mut self.actuator_field);
                            controls::show(ui, &self.params, &self.feed, &setter);
                            ui.separator();
                            // VST3 hosts pass no CCs (see `SakeGlugPlugin`).
                            let raw_midi = gui.plugin_api() != PluginApi::Vst3;
                            self.midi_edited |= midi_settings::show(
                                ui,
                                &self.params,
                                &mut self.midi_panel,
                                raw_midi,
                            );
                            ui.separator();
                            osc_settings::show(ui, &self.params, &self.osc);
                        });
                });
                let width = ui.available_width();
                bottle::show(ui, &self.feed, egui::vec2(width, 220.0));
            });
            if self.midi_edited && !ui.input(|input| input.pointer.any_down()) {
                self.midi_edited = false;
                midi_settings::tell_host(gui);
            }
            ui.separator();
            ui.horizontal_top(|ui| {
                let width = (ui.available_width() - ui.spacing().item_spacing.x) / 2.0;
                scope::show(ui, &self.feed, egui::vec2(width, PANEL_HEIGHT));
                envelopes::show(ui, &self.feed, egui::vec2(width, PANEL_HEIGHT));
            });
        });
    }

    fn editor_closed(&mut self) {
        self.gui = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sake_glug_engine::ModelConfig;

    /// Runs the drawings in a headless egui frame; returns the number of shapes painted.
    fn paint(feed: &Feed, params: &GlugParams) -> usize {
        let ctx = egui::Context::default();
        let mut output = ctx.run_ui(egui::RawInput::default(), |ui| {
            bottle::show(ui, feed, egui::vec2(420.0, 220.0));
            scope::show(ui, feed, egui::vec2(370.0, 200.0));
            envelopes::show(ui, feed, egui::vec2(370.0, 200.0));
            midi_settings::show(ui, params, &mut midi_settings::MidiPanel::default(), true);
            osc_settings::show(ui, params, &OscInput::default());
            actuator::show(ui, params, None, &mut PathField::default());
        });
        // Nothing uploads the font atlas here.
        output.textures_delta.clear();
        output.shapes.len()
    }

    #[test]
    fn views_draw_a_pouring_bottle_its_scope_and_envelopes() {
        use std::sync::atomic::Ordering::Relaxed;
        let feed = Feed::default();
        let params = GlugParams::default();
        let idle = paint(&feed, &params);
        assert!(idle > 5, "frames, outlines and labels: {idle}");

        // Feed it a second of pouring, as the audio thread would.
        let mut renderer = crate::RealtimeEngine::new(48_000.0, ModelConfig::default());
        let mut settings = crate::Settings::from_params(&params);
        settings.values.tilt_deg = 135.0;
        let mut block = vec![0.0f32; 48_000];
        renderer.process(&settings, &mut block, &feed);
        assert!(feed.units().count() > 0);
        assert_eq!(feed.tilt_deg.load(Relaxed), 135.0);
        assert!(feed.volume_ml.load(Relaxed) < 300.0);
        let busy = paint(&feed, &params);
        assert!(
            busy > idle + 8,
            "scope columns and envelope curves: {busy} vs {idle}"
        );
    }
}
