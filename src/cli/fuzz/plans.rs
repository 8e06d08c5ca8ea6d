//! Running the plans target's cases, `pinfeed plan` argument sets: a part and a short time limit (≤ 1 s), small line checks, one
//! thread and no files, plus 0–4 more flags from
//! [`pinfeed::study::robustness::commands::PLAN_FLAGS`] with values inside, at the ends of
//! and beyond their ranges. The arguments go through the command's own parser and checks
//! ([`crate::plan::options_of`]) and the design workflow ([`pinfeed::plan::design::design`]);
//! an accepted design's numbers must be finite and the scenario it would write (with its policy
//! file) must be accepted by the scenario parser and run ([`files::check_scenario`]) — a
//! written plan the parser refuses counts as a self-check disagreement.

use crate::plan::PlanArgs;
use clap::Parser;
use pinfeed::study::robustness::commands::{plan_arguments, plan_command};
use pinfeed::study::robustness::{
    files, refused, shows_non_finite, CaseReport, Class, CommandCases,
};
use std::path::Path;

/// The cases of the plans target, for the fuzzing driver.
pub const CASES: CommandCases = CommandCases {
    run: |rng, scratch| run(&plan_arguments(rng), scratch),
    input: |rng| plan_command(&plan_arguments(rng)),
};

#[derive(Parser)]
#[command(name = "plan")]
struct PlanCommand {
    #[command(flatten)]
    args: PlanArgs,
}

/// Run a case's arguments; `scratch` is a fresh folder for the written scenario.
pub fn run(args: &[String], scratch: &Path) -> CaseReport {
    let mut r = run_unlabelled(args, scratch);
    if r.class.is_problem() {
        r.detail = format!("{}: {}", plan_command(args), r.detail);
    }
    r
}

fn run_unlabelled(args: &[String], scratch: &Path) -> CaseReport {
    let argv = std::iter::once("plan".to_string()).chain(args.iter().cloned());
    let parsed = match PlanCommand::try_parse_from(argv) {
        Ok(p) => p.args,
        Err(e) => return refused(&e.to_string()),
    };
    let o = match crate::plan::options_of(&parsed, &plan_command(args)) {
        Ok(o) => o,
        Err(e) => return refused(&format!("{e:#}")),
    };
    let d = match pinfeed::plan::design::design(&o, &|_| {}) {
        Ok(d) => d,
        Err(e) => return refused(&e.to_string()),
    };
    if shows_non_finite(&format!("{d:?}")) {
        return CaseReport::with(Class::NonFinite, "the design holds NaN or inf");
    }
    let Some(toml) = &d.scenario_toml else {
        return CaseReport::new(Class::Success);
    };
    let _ = std::fs::create_dir_all(scratch);
    if let Some((name, text)) = &d.policy_toml {
        let file = Path::new(name).file_name().unwrap_or_default();
        if let Err(e) = std::fs::write(scratch.join(file), text) {
            return CaseReport::with(Class::Named, format!("cannot write the policy: {e}"));
        }
    }
    let written = files::check_scenario(&scratch.join("plan.toml"), toml);
    match written.class {
        Class::Success => CaseReport::new(Class::Success),
        Class::Located | Class::Named | Class::Unlocated => CaseReport::with(
            Class::Disagreement,
            format!(
                "the scenario the design writes is refused ({:?}{})",
                written.class,
                if written.detail.is_empty() {
                    String::new()
                } else {
                    format!(": {}", written.detail)
                }
            ),
        ),
        _ => written,
    }
}
