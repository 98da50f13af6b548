//! `Surface::new` on arbitrary arrays (see `curvetet_fuzz::surface_arrays`).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| curvetet_fuzz::surface_arrays(data));
