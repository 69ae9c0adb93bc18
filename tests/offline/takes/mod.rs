//! Reading recorded takes: Standard MIDI Files and CSV logs, exactly and never with a panic;
//! and a take rendered offline as the plugin renders the same messages.

mod csv_lane;
mod fuzz;
mod midi_take;
mod rendered;
