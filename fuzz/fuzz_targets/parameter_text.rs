#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| sake_glug_fuzz::checks::parameter_text(data));
