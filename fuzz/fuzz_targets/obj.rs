#![no_main]
//! OBJ parsing from bytes. The path names a folder that does not exist, so `mtllib` lines
//! fail cleanly instead of reading the machine's files.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = glint::io::obj::parse_obj_bytes(data, std::path::Path::new("/nonexistent-glint-fuzz/in.obj"));
});
