#![no_main]
//! The Mitsuba XML reader on arbitrary text (includes resolve next to a path that does not
//! exist, so they fail cleanly).
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = glint::formats::mitsuba::read_str(text, std::path::Path::new("/nonexistent/fuzz.xml"), &[]);
    }
});
