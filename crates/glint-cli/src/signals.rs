//! Ctrl-C and SIGTERM: the first asks the render to stop after the current pass (the image
//! so far is written); a second ends the process at once, removing the temporary files of
//! any write under way so that nothing half-written is left behind.

use std::ffi::CString;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicPtr, AtomicU32, Ordering};

/// Set by the first signal; the render loop polls it.
pub static CANCEL: AtomicBool = AtomicBool::new(false);
static SIGNAL: AtomicI32 = AtomicI32::new(0);
static COUNT: AtomicU32 = AtomicU32::new(0);

/// Temporary files to remove on a hard exit (at most this many outputs per render).
const MAX_TEMPS: usize = 64;
static TEMPS: [AtomicPtr<std::ffi::c_char>; MAX_TEMPS] = [const { AtomicPtr::new(std::ptr::null_mut()) }; MAX_TEMPS];

/// SIGINT's number (Ctrl-C), whose exit code a render stopped from its preview gives too.
pub const SIGINT: i32 = 2;

/// The signal that stopped the render, if one did.
pub fn received() -> Option<i32> {
    match SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// The exit code for a render stopped by `signal` (128 + its number: 130 for SIGINT).
pub fn exit_code(signal: i32) -> i32 {
    128 + signal
}

/// Remembers a temporary path that an atomic write may create, so that a second signal can
/// remove it. The strings are leaked on purpose: the handler may read them at any time.
pub fn register_temp(path: &Path) {
    let Ok(c) = CString::new(path.as_os_str().as_encoded_bytes()) else { return };
    let ptr = c.into_raw();
    for slot in &TEMPS {
        if slot.compare_exchange(std::ptr::null_mut(), ptr, Ordering::SeqCst, Ordering::SeqCst).is_ok() {
            return;
        }
    }
    // SAFETY: `ptr` came from `CString::into_raw` just above and was not stored anywhere.
    drop(unsafe { CString::from_raw(ptr) });
}

#[cfg(unix)]
extern "C" fn on_signal(sig: libc::c_int) {
    // Only async-signal-safe work here: atomics, unlink and _exit.
    let n = COUNT.fetch_add(1, Ordering::SeqCst) + 1;
    SIGNAL.store(sig, Ordering::SeqCst);
    CANCEL.store(true, Ordering::SeqCst);
    if n >= 2 {
        for slot in &TEMPS {
            let p = slot.load(Ordering::SeqCst);
            if !p.is_null() {
                // SAFETY: every non-null slot holds a NUL-terminated string leaked by
                // `register_temp` and never freed; unlink only reads it.
                unsafe { libc::unlink(p) };
            }
        }
        // SAFETY: _exit is async-signal-safe and takes any status.
        unsafe { libc::_exit(exit_code(sig)) };
    }
}

/// Installs the handler for SIGINT and SIGTERM (elsewhere than Unix, the default action).
pub fn install() {
    #[cfg(unix)]
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: `sigaction` is given a zeroed struct with a valid handler address and an
        // empty mask; the handler only does async-signal-safe work.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as usize;
            libc::sigemptyset(&mut action.sa_mask);
            action.sa_flags = libc::SA_RESTART;
            libc::sigaction(sig, &action, std::ptr::null_mut());
        }
    }
}
