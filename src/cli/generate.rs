//! `axcomp completions SHELL` and `axcomp man [COMMAND]`: the shell
//! completions and the manual pages, generated from the clap definitions
//! (`super::command`), so they cannot drift from the flags.

use std::io::Write;

use anyhow::{Context, Result, bail};
use clap::Args;
use clap_complete::Shell;

/// Flags of `axcomp completions`.
#[derive(Debug, Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, powershell or elvish.
    ///
    /// For bash, for example: `axcomp completions bash >
    /// ~/.local/share/bash-completion/completions/axcomp`.
    #[arg(value_name = "SHELL")]
    pub shell: Shell,
}

/// Flags of `axcomp man`.
#[derive(Debug, Args)]
pub struct ManArgs {
    /// The command whose page to print (convert, report, …); without it,
    /// the page of axcomp itself, which lists the commands.
    ///
    /// For example: `axcomp man > axcomp.1 && man ./axcomp.1`, `axcomp man
    /// convert > axcomp-convert.1`.
    #[arg(value_name = "COMMAND")]
    pub command: Option<String>,
}

/// Prints the completion script for the shell.
pub fn completions(args: &CompletionsArgs) -> Result<()> {
    let mut command = super::command();
    let mut stdout = std::io::stdout().lock();
    clap_complete::generate(args.shell, &mut command, "axcomp", &mut stdout);
    stdout.flush().context("writing the completions")?;
    Ok(())
}

/// Prints the roff manual page of axcomp or of one of its commands.
pub fn man(args: &ManArgs) -> Result<()> {
    let top = super::command();
    let page = match &args.command {
        None => top,
        Some(name) => {
            let Some(sub) = top.find_subcommand(name) else {
                let names: Vec<&str> = top.get_subcommands().map(|s| s.get_name()).collect();
                bail!(
                    "axcomp has no command {name:?}: expected one of {}",
                    names.join(", ")
                );
            };
            // The page is named as man(1) finds it: axcomp-convert(1).
            let name = format!("axcomp-{}", sub.get_name());
            sub.clone()
                .name(name.clone())
                .bin_name(name)
                .version(env!("CARGO_PKG_VERSION"))
        }
    };
    let mut roff = Vec::new();
    clap_mangen::Man::new(page)
        .render(&mut roff)
        .context("rendering the manual page")?;
    let mut stdout = std::io::stdout().lock();
    stdout.write_all(&roff).context("writing the manual page")?;
    Ok(())
}
