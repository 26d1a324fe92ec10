#![no_main]
//! Mitsuba's `.serialized` mesh reader on arbitrary bytes; the first byte picks the shape
//! index (a dictionary of several meshes is read through its offset table).
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&index, bytes)) = data.split_first() else { return };
    let _ = glint::io::serialized::parse_serialized(bytes, u32::from(index % 4));
});
