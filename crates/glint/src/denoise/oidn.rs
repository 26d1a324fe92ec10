//! Intel Open Image Denoise 2, loaded at run time so that glint builds and runs without it.
//! The library is the one PyPI's `pyoidn` wheel bundles (these machines have no other):
//! `GLINT_OIDN_LIBRARY` names it, else it is looked for in the `pyoidn` package of the
//! Python interpreter a front end names (Python's own), of `./.venv` and of `python3`, then
//! on the loader's path.

use crate::io::Image;
use crate::math::Rgb;
use std::ffi::{c_char, c_void, CStr, CString};
use std::path::{Path, PathBuf};

const DEVICE_TYPE_CPU: i32 = 1;
const FORMAT_FLOAT3: i32 = 3;
const ERROR_NONE: i32 = 0;
const QUALITY_HIGH: i32 = 6;
const LIBRARY_NAME: &str = "libOpenImageDenoise.so.2";
const INSTALL_HINT: &str =
    "denoising needs Intel Open Image Denoise 2: pip install pyoidn (into ./.venv or python3's site-packages), or set GLINT_OIDN_LIBRARY to libOpenImageDenoise.so.2";

type NewDevice = unsafe extern "C" fn(i32) -> *mut c_void;
type Handle = unsafe extern "C" fn(*mut c_void);
type GetError = unsafe extern "C" fn(*mut c_void, *mut *const c_char) -> i32;
type NewFilter = unsafe extern "C" fn(*mut c_void, *const c_char) -> *mut c_void;
type SetImage = unsafe extern "C" fn(*mut c_void, *const c_char, *mut c_void, i32, usize, usize, usize, usize, usize);
type SetBool = unsafe extern "C" fn(*mut c_void, *const c_char, bool);
type SetInt = unsafe extern "C" fn(*mut c_void, *const c_char, i32);

/// The entry points glint uses, resolved from the loaded library.
pub struct Oidn {
    new_device: NewDevice,
    commit_device: Handle,
    release_device: Handle,
    get_error: GetError,
    new_filter: NewFilter,
    set_image: SetImage,
    set_bool: SetBool,
    set_int: SetInt,
    commit_filter: Handle,
    execute_filter: Handle,
    release_filter: Handle,
}

/// Where the library may be, most specific first.
fn candidates(python: Option<&Path>) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Some(p) = std::env::var_os("GLINT_OIDN_LIBRARY") {
        return vec![PathBuf::from(p)];
    }
    let pythons = python.into_iter().chain([Path::new(".venv/bin/python"), Path::new("python3")]);
    for python in pythons {
        let probe = std::process::Command::new(python)
            .args(["-c", "import os, pyoidn; print(os.path.dirname(pyoidn.__file__))"])
            .stderr(std::process::Stdio::null())
            .output();
        if let Some(o) = probe.ok().filter(|o| o.status.success()) {
            let dir = PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()).join("oidn").join("lib");
            out.push(dir.join(LIBRARY_NAME));
        }
    }
    out.push(PathBuf::from(LIBRARY_NAME));
    out
}

impl Oidn {
    /// Loads the library, or says in one line how to install it.
    pub fn load(python: Option<&Path>) -> Result<Oidn, String> {
        for path in candidates(python) {
            let Ok(c) = CString::new(path.as_os_str().as_encoded_bytes()) else { continue };
            // SAFETY: `c` is a NUL-terminated path; dlopen runs the library's initialisers,
            // which for OIDN only register its devices.
            let lib = unsafe { libc::dlopen(c.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
            if lib.is_null() {
                continue;
            }
            return Oidn::resolve(lib)
                .ok_or_else(|| format!("{}: not an Open Image Denoise 2 library", path.display()));
        }
        Err(INSTALL_HINT.to_string())
    }

    fn resolve(lib: *mut c_void) -> Option<Oidn> {
        let sym = |name: &str| -> Option<*mut c_void> {
            let c = CString::new(name).ok()?;
            // SAFETY: `lib` is a live handle from dlopen (never closed) and `c` a
            // NUL-terminated name.
            let p = unsafe { libc::dlsym(lib, c.as_ptr()) };
            (!p.is_null()).then_some(p)
        };
        // SAFETY: each symbol is the OIDN 2 C function of that name, whose signature (from
        // OpenImageDenoise/oidn.h) is the type it is transmuted to.
        unsafe {
            Some(Oidn {
                new_device: std::mem::transmute::<*mut c_void, NewDevice>(sym("oidnNewDevice")?),
                commit_device: std::mem::transmute::<*mut c_void, Handle>(sym("oidnCommitDevice")?),
                release_device: std::mem::transmute::<*mut c_void, Handle>(sym("oidnReleaseDevice")?),
                get_error: std::mem::transmute::<*mut c_void, GetError>(sym("oidnGetDeviceError")?),
                new_filter: std::mem::transmute::<*mut c_void, NewFilter>(sym("oidnNewFilter")?),
                set_image: std::mem::transmute::<*mut c_void, SetImage>(sym("oidnSetSharedFilterImage")?),
                set_bool: std::mem::transmute::<*mut c_void, SetBool>(sym("oidnSetFilterBool")?),
                set_int: std::mem::transmute::<*mut c_void, SetInt>(sym("oidnSetFilterInt")?),
                commit_filter: std::mem::transmute::<*mut c_void, Handle>(sym("oidnCommitFilter")?),
                execute_filter: std::mem::transmute::<*mut c_void, Handle>(sym("oidnExecuteFilter")?),
                release_filter: std::mem::transmute::<*mut c_void, Handle>(sym("oidnReleaseFilter")?),
            })
        }
    }

    /// Denoises `color`, guided by `albedo` and `normal` where given (same size; each is
    /// prefiltered first and the image then filtered with `cleanAux`).
    pub fn denoise(&self, color: &Image, albedo: Option<&Image>, normal: Option<&Image>) -> Result<Image, String> {
        let (w, h) = (color.width, color.height);
        if albedo.iter().chain(&normal).any(|g| (g.width, g.height) != (w, h)) {
            return Err("denoise: the guide layers and the image differ in size".into());
        }
        // SAFETY: a null device is checked; the device is released on every path below.
        let device = unsafe { (self.new_device)(DEVICE_TYPE_CPU) };
        if device.is_null() {
            return Err("Open Image Denoise: no CPU device".into());
        }
        let result = (|| {
            // SAFETY: `device` is a live device handle.
            unsafe { (self.commit_device)(device) };
            self.check(device)?;
            let mut aux = Vec::new();
            for (name, guide) in [("albedo", albedo), ("normal", normal)] {
                if let Some(g) = guide {
                    aux.push((name, self.filter(device, &[(name, g)], w, h, &[])?));
                }
            }
            let mut inputs = vec![("color", color)];
            inputs.extend(aux.iter().map(|(name, img)| (*name, img)));
            self.filter(device, &inputs, w, h, &[("hdr", true), ("cleanAux", !aux.is_empty())])
        })();
        // SAFETY: `device` is live and released once.
        unsafe { (self.release_device)(device) };
        result
    }

    fn check(&self, device: *mut c_void) -> Result<(), String> {
        let mut msg: *const c_char = std::ptr::null();
        // SAFETY: `device` is live; OIDN writes a pointer to a NUL-terminated message it owns
        // (or leaves it null), valid until the next call on the device.
        let code = unsafe { (self.get_error)(device, &mut msg) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let text = if msg.is_null() {
            format!("error {code}")
        } else {
            // SAFETY: non-null `msg` points at OIDN's NUL-terminated message (see above).
            unsafe { CStr::from_ptr(msg) }.to_string_lossy().into_owned()
        };
        Err(format!("Open Image Denoise: {text}"))
    }

    /// One run of the "RT" filter on shared images; returns its output.
    fn filter(
        &self,
        device: *mut c_void,
        inputs: &[(&str, &Image)],
        w: usize,
        h: usize,
        flags: &[(&str, bool)],
    ) -> Result<Image, String> {
        let flat = |img: &Image| -> Vec<f32> { img.pixels.iter().flat_map(|p| p.to_array()).collect() };
        let input_data: Vec<Vec<f32>> = inputs.iter().map(|(_, img)| flat(img)).collect();
        let mut output = vec![0.0f32; w * h * 3];
        let rt = CString::new("RT").expect("no NUL");
        // SAFETY: `device` is live; a null filter is checked.
        let filter = unsafe { (self.new_filter)(device, rt.as_ptr()) };
        if filter.is_null() {
            self.check(device)?;
            return Err("Open Image Denoise: cannot make the RT filter".into());
        }
        let names: Vec<CString> = inputs.iter().map(|(n, _)| CString::new(*n).expect("no NUL")).collect();
        let out_name = CString::new("output").expect("no NUL");
        let quality = CString::new("quality").expect("no NUL");
        let flag_names: Vec<CString> = flags.iter().map(|(n, _)| CString::new(*n).expect("no NUL")).collect();
        // SAFETY: every buffer holds exactly w*h*3 f32 (packed RGB, so strides of 0), and all
        // outlive the filter, which is released at the end of this block; OIDN only reads the
        // inputs (the const-to-mut cast is never written through) and writes only `output`.
        // The name strings outlive the calls.
        unsafe {
            for (data, name) in input_data.iter().zip(&names) {
                (self.set_image)(filter, name.as_ptr(), data.as_ptr() as *mut c_void, FORMAT_FLOAT3, w, h, 0, 0, 0);
            }
            (self.set_image)(
                filter,
                out_name.as_ptr(),
                output.as_mut_ptr() as *mut c_void,
                FORMAT_FLOAT3,
                w,
                h,
                0,
                0,
                0,
            );
            for ((_, v), name) in flags.iter().zip(&flag_names) {
                (self.set_bool)(filter, name.as_ptr(), *v);
            }
            (self.set_int)(filter, quality.as_ptr(), QUALITY_HIGH);
            (self.commit_filter)(filter);
            (self.execute_filter)(filter);
            (self.release_filter)(filter);
        }
        self.check(device)?;
        if output.iter().any(|v| !v.is_finite()) {
            return Err("Open Image Denoise returned non-finite pixels".into());
        }
        let mut img = Image::new(w, h);
        for (p, c) in img.pixels.iter_mut().zip(output.chunks_exact(3)) {
            *p = Rgb { r: c[0], g: c[1], b: c[2] };
        }
        Ok(img)
    }
}
