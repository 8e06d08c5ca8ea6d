//! The one way a command records the command line that made its output (a report's header, a
//! design file's `command`, …): `pinfeed`, the sub-command path, then every argument the user gave
//! on the command line, in the order the command defines them, each value quoted for a POSIX shell.
//! Defaults are not spelled out: every output also records the pinfeed version, whose defaults
//! they are. Arguments that change only how a result is shown or how fast it is computed
//! ([`NOT_RECORDED`]) are left out, so the same result has the same recorded command.

use clap::parser::ValueSource;
use clap::{ArgMatches, Command};
use pinfeed::output::shell_word;

/// Arguments never recorded: threads, progress display, JSON on standard output, the map cache's
/// folder. None of them changes a result.
pub const NOT_RECORDED: [&str; 4] = ["threads", "quiet", "json", "cache_dir"];

/// The recorded command line of `matches`, parsed by `cmd` (the whole `pinfeed` command).
pub fn command_line(cmd: &Command, matches: &ArgMatches) -> String {
    let mut words = vec![cmd.get_name().to_string()];
    let (mut cmd, mut m) = (cmd, matches);
    loop {
        words.extend(arguments(cmd, m));
        match m.subcommand() {
            Some((name, sub)) => {
                cmd = match cmd.find_subcommand(name) {
                    Some(c) => c,
                    None => break,
                };
                words.push(name.to_string());
                m = sub;
            }
            None => break,
        }
    }
    words.join(" ")
}

/// The words of the arguments given on the command line to one (sub-)command, in definition
/// order: positional values first, then `--long value` (`--long=value` when the value starts
/// with `-`), switches as `--long`.
fn arguments(cmd: &Command, m: &ArgMatches) -> Vec<String> {
    let given = |id: &str| {
        !NOT_RECORDED.contains(&id)
            && matches!(m.try_contains_id(id), Ok(true))
            && m.value_source(id) == Some(ValueSource::CommandLine)
    };
    let values = |id: &str| -> Vec<String> {
        m.get_raw(id)
            .map(|v| v.map(|s| s.to_string_lossy().into_owned()).collect())
            .unwrap_or_default()
    };
    let mut positional = Vec::new();
    let mut options = Vec::new();
    for arg in cmd.get_arguments() {
        let id = arg.get_id().as_str();
        if !given(id) {
            continue;
        }
        let Some(long) = arg.get_long() else {
            positional.extend(values(id).iter().map(|v| shell_word(v)));
            continue;
        };
        if !arg.get_action().takes_values() {
            options.push(format!("--{long}"));
            continue;
        }
        let vs = values(id);
        let value = match arg.get_value_delimiter() {
            Some(sep) => vec![vs.join(&sep.to_string())],
            None => vs,
        };
        for v in value {
            let w = shell_word(&v);
            options.push(if v.starts_with('-') {
                format!("--{long}={w}")
            } else {
                format!("--{long} {w}")
            });
        }
    }
    positional.extend(options);
    positional
}
