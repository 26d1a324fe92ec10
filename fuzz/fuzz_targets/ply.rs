#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = glint::io::ply::parse_ply(data, std::path::Path::new("in.ply"));
});
