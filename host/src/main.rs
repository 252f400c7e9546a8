//! The `twinpath` command line: one module per subcommand under `cli/`.

mod cli;

use clap::Parser;

fn main() {
    if let Err(e) = cli::Cli::parse().run() {
        eprintln!("twinpath: error: {e:#}");
        std::process::exit(1);
    }
}
