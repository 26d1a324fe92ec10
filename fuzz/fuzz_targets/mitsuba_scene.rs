#![no_main]
//! The Mitsuba XML reader on arbitrary text, with `<include>`s resolved in memory: the input
//! is split at NUL bytes into the scene (`/fuzz/scene.xml`) and up to seven files it may
//! include (`/fuzz/inc1.xml` ... `/fuzz/inc7.xml`). Nothing is read from the disk.
use libfuzzer_sys::fuzz_target;
use std::collections::HashMap;
use std::path::PathBuf;

fuzz_target!(|data: &[u8]| {
    let mut parts = data.split(|&b| b == 0).map(std::str::from_utf8);
    let Some(Ok(scene)) = parts.next() else { return };
    let mut files = HashMap::new();
    for (i, part) in parts.take(7).enumerate() {
        if let Ok(text) = part {
            files.insert(PathBuf::from(format!("/fuzz/inc{}.xml", i + 1)), text.to_string());
        }
    }
    let _ = glint::formats::mitsuba::read_str_with_includes(scene, std::path::Path::new("/fuzz/scene.xml"), &[], &files);
});
