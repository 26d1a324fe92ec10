#![no_main]
//! The native JSON reader on arbitrary text (mesh and texture files it names do not exist,
//! so only the reader and the description are exercised).
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = glint::formats::json::read(std::path::Path::new("fuzz.json"), text);
    }
});
