//! The `halo4d` command line: the commands and flags (`cli`), and what each does
//! (`commands`).

mod cli;
mod commands;
mod terminal;

use clap::Parser;
use cli::{Cli, Command};
use std::process::ExitCode;

fn main() -> ExitCode {
    let outcome = match Cli::parse().command {
        Command::Build(args) => commands::build(args),
        Command::Sweep(args) => commands::sweep(args),
        Command::Render(args) => commands::render(args),
        Command::Animate(args) => commands::animate(args),
        Command::List => commands::list(),
        Command::Gallery(args) => commands::gallery(args),
        Command::View(args) => commands::view(args),
        Command::Check(args) => commands::check(args),
        Command::Slice(args) => commands::slice(args),
    };
    outcome.unwrap_or_else(|e| {
        eprintln!("error: {e}");
        ExitCode::FAILURE
    })
}
