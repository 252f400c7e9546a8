//! The `twinpath` command line: one module per subcommand under `cli/`.

mod cli;

use clap::Parser;

fn main() {
    restore_broken_pipe_exit();
    if let Err(e) = cli::Cli::parse().run() {
        eprintln!("twinpath: error: {e:#}");
        std::process::exit(1);
    }
}

/// Lets a closed pipe end the process quietly, as it ends other command-line tools
/// (`twinpath info | head -3`): Rust's runtime ignores SIGPIPE, so a write to a closed pipe
/// fails and `println!` panics with a backtrace instead. Restoring the default action makes the
/// write end the process by the signal, which shells do not report.
fn restore_broken_pipe_exit() {
    #[cfg(unix)]
    // SAFETY: called first in `main`, before any thread exists; SIG_DFL is a valid action for
    // SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
