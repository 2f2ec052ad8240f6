//! `axcomp completions` and `axcomp man`: generated from the flags, so every
//! command and flag that `--help` lists is in them.

use crate::util::axcomp;

/// The commands `axcomp --help` lists (the lines under "Commands:").
fn commands() -> Vec<String> {
    let help = axcomp(["--help"]).stdout;
    let listed = help
        .split("Commands:")
        .nth(1)
        .expect("a Commands: section")
        .split("\n\n")
        .next()
        .unwrap();
    listed
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

/// The long flags `axcomp COMMAND --help` lists.
fn long_flags(command: &str) -> Vec<String> {
    let help = axcomp([command, "--help"]).stdout;
    help.split_whitespace()
        .filter(|word| word.starts_with("--") && word.len() > 2)
        .map(|word| word.trim_end_matches([',', '.']).to_string())
        .map(|word| word.split(['=', '[', '<']).next().unwrap().to_string())
        .filter(|word| word != "--help" && word != "--version")
        .collect()
}

#[test]
fn every_shell_completes_every_command_and_flag() {
    let commands = commands();
    assert!(commands.len() >= 12, "{commands:?}");
    assert!(commands.contains(&"convert".to_string()));
    for shell in ["bash", "zsh", "fish", "powershell"] {
        let run = axcomp(["completions", shell]);
        assert_eq!(run.code, 0, "{shell}: {}", run.stderr);
        for command in &commands {
            assert!(run.stdout.contains(command.as_str()), "{shell}: {command}");
        }
        for flag in ["controller", "stiffness-n-per-um", "existing"] {
            // fish names a long flag `-l controller`, the others `--controller`.
            let written = if shell == "fish" {
                format!("-l {flag}")
            } else {
                format!("--{flag}")
            };
            assert!(run.stdout.contains(&written), "{shell}: {written}");
        }
    }
    let run = axcomp(["completions", "tcsh"]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr.contains("invalid value 'tcsh'"),
        "{}",
        run.stderr
    );
}

#[test]
fn the_manual_pages_hold_every_command_and_its_flags() {
    let top = axcomp(["man"]);
    assert_eq!(top.code, 0, "{}", top.stderr);
    assert!(top.stdout.contains(".TH axcomp 1"), "{}", top.stdout);
    for command in commands() {
        // roff escapes the hyphen: servo-sim is servo\-sim.
        let roff_name = command.replace('-', "\\-");
        assert!(
            top.stdout.contains(&format!("axcomp\\-{roff_name}(1)")),
            "{command} not listed"
        );
        let page = axcomp(["man", &command]);
        assert_eq!(page.code, 0, "{command}: {}", page.stderr);
        assert!(
            page.stdout.contains(&format!(
                ".TH axcomp-{command} 1  \"axcomp-{command} {}\"",
                env!("CARGO_PKG_VERSION")
            )),
            "{command}: {}",
            &page.stdout[..page.stdout.len().min(300)]
        );
        for flag in long_flags(&command) {
            let roff_flag = flag.replace('-', "\\-");
            assert!(
                page.stdout.contains(&roff_flag),
                "axcomp man {command}: {flag} missing"
            );
        }
    }
    let run = axcomp(["man", "nosuch"]);
    assert_eq!(run.code, 2);
    assert!(
        run.stderr
            .contains("axcomp has no command \"nosuch\": expected one of demo"),
        "{}",
        run.stderr
    );
}
