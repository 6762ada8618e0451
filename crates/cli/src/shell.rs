//! `drumroll completions SHELL` and `drumroll man`: shell completion scripts (clap_complete)
//! and manual pages in roff (clap_mangen), generated from the same argument definitions as
//! the parser, so they never fall out of date.

use anyhow::{Context, Result};
use clap::{Args, Command};
use clap_complete::Shell;
use std::path::PathBuf;

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

/// Print the completion script of `args.shell` for `command` on standard output.
pub fn completions(args: &CompletionsArgs, mut command: Command) -> Result<()> {
    let name = command.get_name().to_string();
    clap_complete::generate(args.shell, &mut command, name, &mut std::io::stdout());
    Ok(())
}

/// Print the manual page of `command`, or write every page into `args.out_dir`.
pub fn man(args: &ManArgs, command: Command) -> Result<()> {
    match &args.out_dir {
        None => {
            let mut page = Vec::new();
            clap_mangen::Man::new(command)
                .render(&mut page)
                .context("cannot render the manual page")?;
            use std::io::Write as _;
            std::io::stdout()
                .write_all(&page)
                .context("cannot write to standard output")
        }
        Some(directory) => {
            std::fs::create_dir_all(directory)
                .with_context(|| format!("--out-dir {}: cannot create", directory.display()))?;
            clap_mangen::generate_to(command, directory).with_context(|| {
                format!("--out-dir {}: cannot write the pages", directory.display())
            })?;
            eprintln!("manual pages: {}", directory.display());
            Ok(())
        }
    }
}
