//! Meshes small fuzzed closed surfaces (see `curvetet_fuzz::mesh_icosphere`).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| curvetet_fuzz::mesh_icosphere(data));
