//! SIGINT, SIGTERM and SIGHUP: every command stops cleanly, leaving no temporary file and
//! no partial output, and exits with `128 + signal` (130 for SIGINT).
//!
//! By default a signal removes every pending output ([`sylva_core::io::abandon_pending`])
//! and exits at once. A command that stops by itself between units of work (`render`, which
//! must also stop its ffmpeg child) asks for [`graceful`] handling: the first signal only
//! raises [`interrupted`], and a second one exits at once.

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

/// The signal received, 0 before any.
static RECEIVED: AtomicI32 = AtomicI32::new(0);
/// Whether the running command stops by itself on [`interrupted`].
static GRACEFUL: AtomicBool = AtomicBool::new(false);

/// Installs the handler (once, at start-up).
pub fn install() -> anyhow::Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new().name("signals".into()).spawn(move || {
        for sig in signals.forever() {
            let first = RECEIVED.swap(sig, Ordering::SeqCst) == 0;
            if !(first && GRACEFUL.load(Ordering::SeqCst)) {
                exit_now(sig);
            }
        }
    })?;
    Ok(())
}

/// Removes every pending output and exits with `128 + sig`.
fn exit_now(sig: i32) -> ! {
    sylva_core::io::abandon_pending();
    eprintln!("\n{}: stopped; no partial output was written", name(sig));
    std::process::exit(128 + sig)
}

/// The running command checks [`interrupted`] and stops by itself.
pub fn graceful() {
    GRACEFUL.store(true, Ordering::SeqCst);
}

/// Whether a signal has arrived.
pub fn interrupted() -> bool {
    RECEIVED.load(Ordering::SeqCst) != 0
}

/// The exit status for a command that stopped on a signal: `128 + signal`.
pub fn exit_status() -> Option<u8> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        s => Some((128 + s).clamp(0, 255) as u8),
    }
}

/// The signal's name.
pub fn name(sig: i32) -> &'static str {
    match sig {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        SIGHUP => "SIGHUP",
        _ => "signal",
    }
}

/// The received signal's name, if any.
pub fn received() -> Option<&'static str> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        s => Some(name(s)),
    }
}
