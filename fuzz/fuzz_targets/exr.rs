#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = glint::io::image_io::read_exr_bytes(data, std::path::Path::new("in.exr"));
});
