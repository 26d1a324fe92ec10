#![no_main]
//! PNG (and whatever else the content sniffing picks: JPEG, HDR) through glint's decoder.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = glint::io::image_io::decode_raster_bytes(data, std::path::Path::new("in.png"));
});
