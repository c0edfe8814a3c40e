//! The one place glint writes to stdout and stderr. `println!` and `eprintln!` panic when the
//! write fails (`glint render … --json | true` closes the pipe before the summary is printed),
//! so the library uses [`outln!`](crate::outln) and [`errln!`](crate::errln) instead, and
//! `#![warn(clippy::print_stdout, clippy::print_stderr)]` in `lib.rs` keeps it that way.
//!
//! - stdout: a broken pipe means the reader has gone; like `head` users expect, glint then
//!   exits at once, quietly, with code 0 (every file it writes is complete by the time it
//!   prints). Any other error (a full disk behind `>`) is reported on stderr with exit code 1.
//! - stderr: errors are ignored; there is nowhere left to report them.

use std::fmt::Arguments;
use std::io::{ErrorKind, Write};

/// Prints one line on stdout (see the module's notes for what happens when that fails).
#[macro_export]
macro_rules! outln {
    () => { $crate::stdio::out_line(format_args!("")) };
    ($($arg:tt)*) => { $crate::stdio::out_line(format_args!($($arg)*)) };
}

/// Prints one line on stderr, ignoring a closed or broken stderr.
#[macro_export]
macro_rules! errln {
    () => { $crate::stdio::err_line(format_args!("")) };
    ($($arg:tt)*) => { $crate::stdio::err_line(format_args!($($arg)*)) };
}

/// What [`outln!`](crate::outln) calls.
pub fn out_line(args: Arguments) {
    let result = {
        let mut out = std::io::stdout().lock();
        out.write_fmt(args)
            .and_then(|()| out.write_all(b"\n"))
            .and_then(|()| out.flush())
    };
    match result {
        Ok(()) => {}
        Err(e) if e.kind() == ErrorKind::BrokenPipe => std::process::exit(0),
        Err(e) => {
            err_line(format_args!("glint: error: cannot write to stdout: {e}"));
            std::process::exit(1);
        }
    }
}

/// What [`errln!`](crate::errln) calls.
pub fn err_line(args: Arguments) {
    let mut err = std::io::stderr().lock();
    let _ = err
        .write_fmt(args)
        .and_then(|()| err.write_all(b"\n"))
        .and_then(|()| err.flush());
}
