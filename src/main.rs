//! The `wraptree` command line: parses arguments, wires the library's parts together and
//! reports errors as one `error:` line with a non-zero exit.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Die quietly on a closed pipe (`wraptree group --json | head`), as Unix tools do, instead
    // of panicking in `println!`.
    #[cfg(unix)]
    // SAFETY: restoring the default SIGPIPE disposition before any thread starts or any
    // handler is installed; `signal` has no other preconditions.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(code) => code,
        Err(e) => {
            let msg = format!("{e:#}").replace('\n', " ");
            eprintln!("error: {msg}");
            ExitCode::FAILURE
        }
    }
}
