//! `drumroll completions SHELL` and `drumroll man`: shell completion scripts (clap_complete)
//! and manual pages in roff (clap_mangen), generated from the same argument definitions as
//! the parser, so they never fall out of date.

use anyhow::{Context, Result};
use clap::{Args, Command};
use clap_complete::Shell;
use std::path::{Path, PathBuf};

use crate::output::{print_stdout, write_atomically};
use crate::progress::note;

/// Options of `drumroll completions`.
#[derive(Debug, Clone, Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, elvish or powershell.
    #[arg(value_enum)]
    pub shell: Shell,
}

/// Options of `drumroll man`.
#[derive(Debug, Clone, Args)]
pub struct ManArgs {
    /// Write drumroll.1 and one page per subcommand (drumroll-continue.1, ...) into this
    /// directory (created if missing) instead of printing drumroll.1 on standard output.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
}

/// Print the completion script of `args.shell` for `command` on standard output (rendered in
/// memory first, so that a closed pipe or a full disk is an error, never a panic).
pub fn completions(args: &CompletionsArgs, mut command: Command) -> Result<()> {
    let name = command.get_name().to_string();
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut command, name, &mut script);
    print_stdout(&String::from_utf8_lossy(&script))
}

/// Print the manual page of `command`, or write every page into `args.out_dir`: drumroll.1
/// and one page per subcommand (drumroll-continue.1, ...), each rendered in memory and written
/// atomically ([`write_atomically`]), so that a failed run leaves no half-written page.
pub fn man(args: &ManArgs, command: Command) -> Result<()> {
    match &args.out_dir {
        None => {
            let mut page = Vec::new();
            clap_mangen::Man::new(command)
                .render(&mut page)
                .context("cannot render the manual page")?;
            print_stdout(&String::from_utf8_lossy(&page))
        }
        Some(directory) => {
            std::fs::create_dir_all(directory)
                .with_context(|| format!("--out-dir {}: cannot create", directory.display()))?;
            let mut command = command.disable_help_subcommand(true);
            command.build();
            write_pages(command, directory)?;
            note(&format!("manual pages: {}", directory.display()));
            Ok(())
        }
    }
}

/// Write the manual page of `command` and of each of its visible subcommands, recursively,
/// into `directory` (the file names clap_mangen gives them).
fn write_pages(command: Command, directory: &Path) -> Result<()> {
    for subcommand in command.get_subcommands().filter(|s| !s.is_hide_set()) {
        write_pages(subcommand.clone(), directory)?;
    }
    let man = clap_mangen::Man::new(command);
    let mut page = Vec::new();
    man.render(&mut page)
        .context("cannot render a manual page")?;
    let path = directory.join(man.get_filename());
    write_atomically(&path, &page)
        .with_context(|| format!("--out-dir {}: cannot write the pages", directory.display()))
}
