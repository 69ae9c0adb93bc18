#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| sake_glug_fuzz::checks::state(data));

// Mostly well-formed states with hostile values, sometimes libFuzzer's byte edits.
libfuzzer_sys::fuzz_mutator!(|data: &mut [u8], size: usize, max_size: usize, seed: u32| {
    sake_glug_fuzz::hostile_state::mutate(data, size, max_size, seed)
});
