//! The Slurm and Kubernetes examples of docs/cluster.md are consistent, and scripts/slurm_e2e.sh (which runs the
//! Slurm example on a real one-node Slurm, outside CI) runs exactly what docs/cluster.md shows: the script
//! takes the job script and the submit commands from its marked blocks, so this cheap test
//! checks that those blocks exist, fit together (array size, `--shard /N`, merge glob, log folder,
//! a merge that cannot hang) and contain the two size settings the script shrinks.

use pinfeed::study::mc::shard::ShardSpec;

fn read(rel: &str) -> String {
    std::fs::read_to_string(format!("{}/{rel}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// The fenced block after the line `<!-- slurm_e2e: NAME -->` (as the script's `block` extracts
/// it); fails unless the marker occurs exactly once.
fn block(readme: &str, name: &str) -> String {
    let marker = format!("<!-- slurm_e2e: {name} -->");
    let lines: Vec<&str> = readme.lines().collect();
    let at: Vec<usize> = (0..lines.len()).filter(|&i| lines[i] == marker).collect();
    assert_eq!(
        at.len(),
        1,
        "docs/cluster.md: marker {marker} must occur once"
    );
    let open = (at[0] + 1..lines.len())
        .find(|&i| lines[i].starts_with("```"))
        .expect("a fenced block after the marker");
    assert_eq!(open, at[0] + 1, "{marker} must be directly above its block");
    let close = (open + 1..lines.len())
        .find(|&i| lines[i].starts_with("```"))
        .expect("the block is closed");
    lines[open + 1..close].join("\n")
}

/// The value of `#SBATCH --KEY=VALUE` in a job script (without its trailing comment).
fn sbatch(job: &str, key: &str) -> String {
    let prefix = format!("#SBATCH --{key}=");
    let line = job
        .lines()
        .find_map(|l| l.strip_prefix(&prefix))
        .unwrap_or_else(|| panic!("no '{prefix}' in the job script"));
    line.split_whitespace().next().unwrap().to_string()
}

/// `text` without comment lines and trailing ` # comments` (shell and YAML).
fn code(text: &str) -> String {
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .map(|l| l.split_once(" #").map_or(l, |(code, _)| code))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The shard count N of the one `--shard /N` (or `"--shard", "/N"`) in the code of `text`.
fn shard_count(text: &str) -> u64 {
    let text = &code(text);
    assert_eq!(
        text.matches("--shard").count(),
        1,
        "one --shard in:\n{text}"
    );
    let at = text.find("--shard").unwrap();
    let rest = &text[at + "--shard".len()..];
    let slash = rest.find('/').unwrap();
    let digits: String = rest[slash + 1..]
        .chars()
        .take_while(|c| c.is_ascii_digit())
        .collect();
    digits.parse().unwrap()
}

/// The Slurm job: its array covers every shard index once, each task's `--shard /N` resolves (as
/// pinfeed does, from SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_MIN) to a distinct shard whose file
/// the merge glob matches, its log folder is created before submission, and the merge is
/// cancelled rather than left pending when a task fails. Fails if any of these drifts apart.
#[test]
fn readme_slurm_job_fits_together() {
    let readme = read("docs/cluster.md");
    let job = block(&readme, "mc.sh");
    let submit = block(&readme, "submit");

    let array = sbatch(&job, "array");
    let (lo, hi) = array.split_once('-').expect("--array=LO-HI");
    let (lo, hi): (u64, u64) = (lo.parse().unwrap(), hi.parse().unwrap());
    let n = shard_count(&job);
    assert_eq!(
        hi - lo + 1,
        n,
        "--array={array} runs {} tasks for {n} shards",
        hi - lo + 1
    );
    let glob = format!("shards/shard-*-of-{n:04}.json");
    assert!(
        submit.contains(&glob),
        "the merge must read {glob}:\n{submit}"
    );
    let mut files = Vec::new();
    for task in lo..=hi {
        let env = |var: &str| match var {
            "SLURM_ARRAY_TASK_ID" => Some(task.to_string()),
            "SLURM_ARRAY_TASK_MIN" => Some(lo.to_string()),
            _ => None,
        };
        let spec = ShardSpec::parse(&format!("/{n}"), &env).unwrap();
        assert_eq!(spec.index, task - lo);
        files.push(spec.file_name());
    }
    files.dedup();
    assert_eq!(files.len() as u64, n, "two tasks write the same shard");
    assert!(files
        .iter()
        .all(|f| f.ends_with(&format!("-of-{n:04}.json"))));
    // The study the job runs exists, and the job writes where the merge reads.
    let study = job
        .split_whitespace()
        .find(|w| w.starts_with("studies/"))
        .expect("the job runs a bundled study");
    assert!(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join(study)
            .is_file(),
        "{study}"
    );
    assert!(job.contains("--out shards"));

    // Slurm does not create the --output folder: the submit block must, before sbatch.
    let output = sbatch(&job, "output");
    let folder = output.rsplit_once('/').map(|(d, _)| d).unwrap_or(".");
    if folder != "." {
        let mkdir = submit
            .find(&format!("mkdir -p {folder}"))
            .unwrap_or_else(|| panic!("the submit block must create {folder}/:\n{submit}"));
        assert!(mkdir < submit.find("sbatch").unwrap());
    }
    // The merge waits for success, is cancelled when a task fails, and logs where logs go.
    assert!(submit.contains("--dependency=afterok:$jobid"), "{submit}");
    assert!(submit.contains("--kill-on-invalid-dep=yes"), "{submit}");
    assert!(submit.contains(&format!("--output={folder}/")), "{submit}");
    assert!(submit.contains("pinfeed merge") && submit.contains("--quiet"));
}

/// scripts/slurm_e2e.sh runs docs/cluster.md's blocks (by their markers) and shrinks exactly the two size
/// settings it names, which docs/cluster.md's job must contain once each; the script compares the merged
/// report with an unsharded run of the same study. Fails if docs/cluster.md and the script drift apart.
#[test]
fn e2e_script_runs_the_readme_job() {
    let readme = read("docs/cluster.md");
    let script = read("scripts/slurm_e2e.sh");
    let job = block(&readme, "mc.sh");
    assert!(script.contains("job=$(block mc.sh)"));
    assert!(script.contains("submit=$(block submit)"));
    assert!(script.contains(r#"awk -v m="<!-- slurm_e2e: $1 -->""#));
    for setting in ["--samples 100000", "--cpus-per-task=4"] {
        assert_eq!(
            job.matches(setting).count(),
            1,
            "docs/cluster.md's job: {setting}"
        );
        assert!(
            script.contains(&format!("s/{setting}/")),
            "the script shrinks {setting}"
        );
    }
    let study = job
        .split_whitespace()
        .find(|w| w.starts_with("studies/"))
        .unwrap();
    assert!(
        script.contains(&format!("study={study}\n")),
        "the script's unsharded run must be of {study}"
    );
    // The merge writes pinfeed-out/mc/<study name>/ (no --out in docs/cluster.md's merge): the script
    // compares that folder.
    let name = read(study)
        .lines()
        .find_map(|l| l.strip_prefix("name = "))
        .map(|v| v.trim().trim_matches('"').to_string())
        .unwrap();
    assert!(script.contains(&format!("report_dir=pinfeed-out/mc/{name}\n")));
}

/// The Kubernetes Indexed Job runs one pod per shard and the merge reads that many shards.
#[test]
fn readme_kubernetes_job_fits_together() {
    let readme = read("docs/cluster.md");
    let at = readme
        .find("completionMode: Indexed")
        .expect("the Kubernetes example");
    let yaml = &readme[at..at + readme[at..].find("```").unwrap()];
    let completions: u64 = yaml
        .lines()
        .find_map(|l| l.trim().strip_prefix("completions:"))
        .and_then(|v| v.split_whitespace().next())
        .unwrap()
        .parse()
        .unwrap();
    let n = shard_count(yaml);
    assert_eq!(completions, n);
    let after = &readme[at..];
    assert!(after.contains(&format!("pinfeed merge /shards/shard-*-of-{n:04}.json")));
}
