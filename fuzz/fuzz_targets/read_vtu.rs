//! The vtu reader on arbitrary bytes, then the surface checks on what it accepts.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| curvetet_fuzz::read(data, curvetet::io::Format::Vtu));
