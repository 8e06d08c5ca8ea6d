//! Measured bands against the model: the synthetic recovery, scoring on hand-made cases
//! (bands across 0°/360° included), thread-count independence, located errors for bad files.

use crate::support::pinfeed;
use pinfeed::maps::ensemble::{ensemble_maps, EnsembleSpec};
use pinfeed::mechanics::Fidelity;
use pinfeed::validate::calibrate::{calibrate, CalibrationSettings};
use pinfeed::validate::measured::{self, Measured};
use pinfeed::validate::score::{score_rows, summarise, ScoreSettings, Verdict};
use pinfeed::validate::synthetic::{synthesize, SyntheticDesign};
use std::path::Path;

const FIXTURE: &str = "tests/fixtures/validate/synthetic.csv";

fn fixture() -> Measured {
    measured::load(Path::new(FIXTURE), 0.5).unwrap()
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// The truth of the bundled data set as an ensemble, with some values replaced.
fn truth_with(settings: &str) -> EnsembleSpec {
    SyntheticDesign::default()
        .truth
        .with_settings(settings)
        .unwrap()
}

#[test]
fn the_bundled_synthetic_data_set_is_what_the_generator_writes() {
    let text = synthesize(&SyntheticDesign::default()).unwrap();
    assert_eq!(text, std::fs::read_to_string(FIXTURE).unwrap());
}

#[test]
fn calibration_recovers_the_hidden_parameters_within_its_intervals() {
    let s = CalibrationSettings {
        jitter_deg: SyntheticDesign::JITTER_DEG,
        ..CalibrationSettings::default()
    };
    let cal = calibrate(&fixture(), &s).unwrap();
    for (p, truth) in cal.parameters.iter().zip(SyntheticDesign::TRUTH) {
        assert!(
            p.covers(truth),
            "{} = {truth} outside [{}, {}]",
            p.name,
            p.lo,
            p.hi
        );
    }
    // Not vacuous: μc mean and pin radius are pinned down by the data, well inside their grids.
    for k in [0, 3] {
        let p = &cal.parameters[k];
        assert!(!p.open_low && !p.open_high, "{p:?}");
        assert!(p.hi - p.lo < 0.5 * (p.grid_max - p.grid_min), "{p:?}");
    }
    assert!(cal.effective_members > 50.0, "{}", cal.effective_members);
}

#[test]
fn validate_scores_the_true_parameters_better_than_wrong_ones() {
    let m = fixture();
    let s = ScoreSettings::default();
    let score = |spec: &EnsembleSpec| {
        pinfeed::validate::validate(&m, spec, 3, 300, 1, &s)
            .unwrap()
            .1
            .log_score
    };
    let truth = score(&SyntheticDesign::default().truth);
    for wrong in [
        "mu_c=0.2,support=uniform,pin_radius=0,jitter=0",
        "mu_c=normal:0.8:0.08",
        "mu_c=normal:0.2:0.08",
        "support=uniform",
        "pin_radius=normal:0.25:0.03",
    ] {
        let w = score(&truth_with(wrong));
        assert!(truth > w + 5.0, "{wrong}: truth {truth} vs {w}");
    }
}

fn hand_made(rows: &str) -> Measured {
    let text = format!("part,d,input,min_deg,max_deg,trials\n{rows}");
    measured::parse(Path::new("hand.csv"), &text, 0.0).unwrap()
}

#[test]
fn containment_overlap_and_coverage_on_hand_made_cases_across_zero() {
    let m = hand_made(
        "tripoly1,0.1,state:0,352,8,10\ntripoly1,0.1,state:0,5,30,10\ntripoly1,0.1,state:0,100,120,10\ntripoly1,0.1,all,355,2,\n",
    );
    // One predicted cluster from 350° round to 10°, evenly spread.
    let cluster: Vec<f64> = (0..200).map(|k| (350.0 + k as f64 * 0.1) % 360.0).collect();
    let preds = vec![cluster; 4];
    let s = ScoreSettings::default();
    let (rows, count) = score_rows(&m, &preds, &vec![1.0; 200], 1, &s);
    let band = &rows[0].predicted.bands;
    assert_eq!(band.len(), 1, "{band:?}");
    // 90% takes 18 of the 20 bins; the 2° gap left at 358° is closed again.
    assert!(
        band[0].arc.lo == 350.0 && (band[0].arc.width - 19.9).abs() < 1e-9,
        "{band:?}"
    );
    // 161 of the 200 passes lie in [352°, 8°]: a share of 0.805, just over the 80% threshold,
    // and 200 members cannot tell it from one just under.
    assert!(rows[0].contained && rows[0].overlapping);
    assert!((rows[0].contained_share - 0.805).abs() < 1e-9);
    assert_eq!(rows[0].containment, Verdict::Undecided);
    assert!(rows[0].centre_offset_deg.unwrap().abs() < 0.2);
    assert!((rows[0].predicted_probability - 0.8).abs() < 0.01);
    assert!(!rows[1].contained && rows[1].overlapping);
    assert!((rows[1].predicted_probability - 0.25).abs() < 0.01);
    assert!(!rows[2].contained && !rows[2].overlapping);
    assert!((rows[2].centre_offset_deg.unwrap() - 110.0).abs() < 0.5);
    assert!(rows[2].predicted_probability == 0.0);
    assert_eq!(rows[1].containment, Verdict::NotContained);
    // Input `all`: the share of the passes within 20° of [355°, 2°] (all of them) inside it.
    assert!((rows[3].contained_share - 0.355).abs() < 1e-9);
    assert!(!rows[3].contained && rows[3].overlapping);
    let summary = summarise(&rows, count, s.contained_share);
    assert_eq!((summary.contained, summary.overlapping), (1, 3));
    assert_eq!(
        (
            summary.verdict_contained,
            summary.verdict_not_contained,
            summary.verdict_undecided
        ),
        (0, 3, 1)
    );
    assert!(count[0] <= 1 && count[1] >= 1, "{count:?}");
    assert!(
        (summary.coverage - 20.0 / 360.0).abs() < 0.001,
        "{}",
        summary.coverage
    );
    // A prediction centred on the measured band scores better than one beside it, and better than
    // one spread over the whole circle (which contains everything).
    let row = hand_made("tripoly1,0.1,state:0,352,8,10\n");
    let shifted: Vec<f64> = (0..200).map(|k| 20.0 + k as f64 * 0.1).collect();
    let everywhere: Vec<f64> = (0..200).map(|k| k as f64 * 1.8).collect();
    let ls = |v: Vec<f64>| score_rows(&row, &[v], &vec![1.0; 200], 1, &s).0[0].log_score;
    let (right, beside, flat) = (ls(preds[0].clone()), ls(shifted), ls(everywhere.clone()));
    assert!(
        right > beside + 10.0 && right > flat + 10.0,
        "{right} {beside} {flat}"
    );
    let spread = score_rows(&row, &[everywhere], &vec![1.0; 200], 1, &s).0;
    assert!(spread[0].predicted.coverage > 0.85);
}

#[test]
fn the_same_inputs_and_seed_give_the_same_report_on_any_number_of_threads() {
    let run = |threads: &str| {
        let out = pinfeed(&[
            "validate",
            FIXTURE,
            "--members",
            "40",
            "--uncertain",
            "mu_c=normal:0.45:0.08,support=tripod:0.6,jitter=3",
            "--json",
            "--no-write",
            "--threads",
            threads,
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out.stdout
    };
    let one = run("1");
    assert_eq!(one, run("3"));
    // The report says what "contained" means, with the threshold, and each row its interval.
    let j: serde_json::Value = serde_json::from_slice(&one).unwrap();
    let means = j["containment"].as_str().unwrap();
    assert!(
        means.contains("at least 80% of the predicted mass"),
        "{means}"
    );
    let row = &j["rows"][0];
    let [lo, hi] = [0, 1].map(|k| row["contained_share_ci95"][k].as_f64().unwrap());
    let share = row["contained_share"].as_f64().unwrap();
    assert!(lo <= share && share <= hi, "{row}");
    assert!(row["containment"].is_string(), "{row}");
    let poly = pinfeed::geometry::part_from_spec("tripoly2").unwrap();
    let spec = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
        .with_settings("mu_c=uniform:0.3:0.7,support=smooth:0.5,jitter=2")
        .unwrap();
    let grid: Vec<f64> = (0..36).map(|k| k as f64 * 10.0).collect();
    let maps = |t: usize| {
        pool(t)
            .install(|| ensemble_maps(&poly, &spec, &[-0.3, 0.5], &grid, 7, 12))
            .unwrap()
    };
    assert_eq!(maps(1), maps(3));
    let s = CalibrationSettings {
        members: 60,
        ..CalibrationSettings::default()
    };
    let m = fixture();
    let cal = |t: usize| pool(t).install(|| calibrate(&m, &s)).unwrap();
    assert_eq!(cal(1), cal(2));
}

#[test]
fn bad_measured_files_give_located_errors() {
    let header = "part,d,input,min_deg,max_deg,trials\n";
    let cases: [(&str, &str); 12] = [
        (
            "tripoly1,0.1,state:0,370,10,5\n",
            "bad.csv:2: field `min_deg`: 370 is out of range",
        ),
        (
            "tripoly1,0.1,state:0,10,-5,5\n",
            "bad.csv:2: field `max_deg`: -5 is out of range",
        ),
        (
            "widget,0.1,state:0,10,20,5\n",
            "bad.csv:2: field `part`: unknown part 'widget'",
        ),
        (
            "tripoly1,1.5,state:0,10,20,5\n",
            "bad.csv:2: field `d`: d = 1.5 is out of range",
        ),
        (
            "tripoly1,x,state:0,10,20,5\n",
            "bad.csv:2: field `d`: 'x' is not a finite number",
        ),
        (
            "tripoly1,0.1,state:7,10,20,5\n",
            "bad.csv:2: field `input`: 'state:7'",
        ),
        (
            "tripoly1,0.1,side,10,20,5\n",
            "bad.csv:2: field `input`: 'side' must be",
        ),
        (
            "tripoly1,0.1,state:0,10,20,0\n",
            "bad.csv:2: field `trials`",
        ),
        (
            "tripoly1,0.1,state:0\n",
            "bad.csv:2: expected 6 comma-separated fields",
        ),
        ("# only a comment\n", "bad.csv:1: no measurement rows"),
        (
            "tripoly1,0.1,state:0,10,20,5\ntripoly1,0.1,state:0,10,20,5,9\n",
            "bad.csv:3: expected 6",
        ),
        (
            "tripoly1,0.1,state:0,10,NaN,5\n",
            "bad.csv:2: field `max_deg`: 'NaN' is not a finite number",
        ),
    ];
    for (rows, want) in cases {
        let e = measured::parse(Path::new("bad.csv"), &format!("{header}{rows}"), 0.0).unwrap_err();
        assert!(e.to_string().starts_with(want), "{rows:?}: {e}");
    }
    for (text, want) in [
        ("", "bad.csv:1: empty file"),
        ("\n# nothing\n", "bad.csv:1: empty file"),
        ("part,d,theta\n", "bad.csv:1: the header must be"),
    ] {
        let e = measured::parse(Path::new("bad.csv"), text, 0.0).unwrap_err();
        assert!(e.to_string().starts_with(want), "{text:?}: {e}");
    }
    // From the command line: a located message and a non-zero exit, never a panic.
    let dir = std::env::temp_dir().join(format!("pinfeed-validate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.csv");
    std::fs::write(
        &bad,
        format!("{header}tripoly1,0.1,state:0,10,20,5\ntripoly1,0.2,all,10,400,\n"),
    )
    .unwrap();
    let empty = dir.join("empty.csv");
    std::fs::write(&empty, "").unwrap();
    for (command, file, want) in [
        ("validate", &bad, ":3: field `max_deg`: 400 is out of range"),
        ("calibrate", &bad, ":3: field `max_deg`"),
        ("validate", &empty, ":1: empty file"),
        ("validate", &dir.join("missing.csv"), "cannot read the file"),
    ] {
        let out = pinfeed(&[command, file.to_str().unwrap(), "--no-write"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{command} {file:?}: {err}");
        assert!(
            err.contains(file.to_str().unwrap()) && err.contains(want),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn map_uncertain_prints_predicted_bands_and_refuses_bad_settings() {
    let ok = pinfeed(&[
        "map",
        "--part",
        "tripoly1",
        "--d=0.3",
        "--theta-step",
        "30",
        "--uncertain",
        "mu_c=normal:0.5:0.1,support=tripod:0.5,pin_radius=uniform:0:0.1,jitter=2",
        "--members",
        "4",
        "--no-write",
    ]);
    let out = String::from_utf8_lossy(&ok.stdout);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    for want in ["| +0.3 | all | 48 |", "| +0.3 | state:2 | 4 |"] {
        assert!(out.contains(want), "{out}");
    }
    for bad in ["mu_c=-0.1", "glue=1", "support=tripod:2"] {
        let o = pinfeed(&[
            "map",
            "--part",
            "tripoly1",
            "--d=0.3",
            "--uncertain",
            bad,
            "--no-write",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{bad}: {err}");
        assert!(
            err.contains("--uncertain") && !err.contains("panicked"),
            "{err}"
        );
    }
}

/// `--part` gives the part of every row, so a measured file for a `vertices:` part needs no part
/// column; a part column with the vertex list quoted as CSV quotes it reads the same; and the
/// report names `--part` in its command.
#[test]
fn validate_takes_part_for_a_vertex_list() {
    let dir = std::env::temp_dir().join(format!("pinfeed-validate-part-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let part = "vertices:0,0 36,0 8,22";
    let bare = dir.join("bare.csv");
    std::fs::write(
        &bare,
        "d,input,min_deg,max_deg,trials\n0.2,state:0,0,40,10\n-0.3,all,100,200,\n",
    )
    .unwrap();
    let quoted = dir.join("quoted.csv");
    std::fs::write(
        &quoted,
        format!("part,d,input,min_deg,max_deg,trials\n\"{part}\",0.2,state:0,0,40,10\n\"{part}\",-0.3,all,100,200,\n"),
    )
    .unwrap();
    let run = |file: &std::path::Path, extra: &[&str]| {
        let mut args = vec![
            "validate",
            file.to_str().unwrap(),
            "--members",
            "8",
            "--json",
            "--no-write",
        ];
        args.extend_from_slice(extra);
        crate::support::pinfeed(&args)
    };
    let a = run(&bare, &["--part", part]);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = run(&quoted, &[]);
    assert!(b.status.success(), "{}", String::from_utf8_lossy(&b.stderr));
    let ja: serde_json::Value = serde_json::from_slice(&a.stdout).unwrap();
    let jb: serde_json::Value = serde_json::from_slice(&b.stdout).unwrap();
    assert_eq!(ja["schema_version"], pinfeed::SCHEMA_VERSION);
    assert_eq!(ja["rows"].as_array().unwrap().len(), 2);
    assert_eq!(ja["rows"][0]["part"], part);
    assert_eq!(ja["rows"], jb["rows"]);
    assert!(
        ja["command"]
            .as_str()
            .unwrap()
            .contains("--part 'vertices:0,0 36,0 8,22'"),
        "{}",
        ja["command"]
    );
    // --part replaces a named part column.
    let named = dir.join("named.csv");
    std::fs::write(
        &named,
        "part,d,input,min_deg,max_deg\ntripoly1,0.2,state:0,0,40\n",
    )
    .unwrap();
    let c = run(&named, &["--part", part]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let jc: serde_json::Value = serde_json::from_slice(&c.stdout).unwrap();
    assert_eq!(jc["rows"][0]["part"], part);
    // Without --part, a file with no part column is refused, naming the flag; an unclosed quote
    // is refused naming the line.
    let d = run(&bare, &[]);
    assert!(!d.status.success());
    let e = String::from_utf8_lossy(&d.stderr);
    assert!(
        e.contains("no `part` column") && e.contains("--part"),
        "{e}"
    );
    std::fs::write(
        &quoted,
        format!("part,d,input,min_deg,max_deg\n\"{part},0.2,state:0,0,40\n"),
    )
    .unwrap();
    let f = run(&quoted, &[]);
    assert!(!f.status.success());
    let e = String::from_utf8_lossy(&f.stderr);
    assert!(
        e.contains("quoted.csv:2") && e.contains("not closed"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A prediction with 95% of its mass inside the measured band is contained, one with 60% is not,
/// whatever the seed of the members drawn; the verdicts carry their bootstrap intervals.
#[test]
fn a_prediction_with_95_percent_of_its_mass_inside_is_contained_at_every_seed() {
    use pinfeed::random::ChaCha8Rng;
    use rand::RngExt;
    let m = hand_made("tripoly1,0.1,state:0,350,10,20\n");
    let s = ScoreSettings::default();
    for seed in 1..=3u64 {
        let mut rng = pinfeed::random::stream(seed, 0);
        // 500 members: each lands inside (±9°) with probability p, else near 180°.
        let draw = |rng: &mut ChaCha8Rng, p: f64| -> Vec<f64> {
            (0..500)
                .map(|_| {
                    let u: f64 = rng.random();
                    let x: f64 = rng.random::<f64>() * 18.0 - 9.0;
                    if u < p {
                        (360.0 + x) % 360.0
                    } else {
                        180.0 + x
                    }
                })
                .collect()
        };
        let inside = draw(&mut rng, 0.95);
        let (rows, count) = score_rows(&m, &[inside], &vec![1.0; 500], 1, &s);
        let r = &rows[0];
        assert!(r.contained, "seed {seed}: {}", r.contained_share);
        assert_eq!(r.containment, Verdict::Contained, "seed {seed}: {r:?}");
        let [lo, hi] = r.contained_share_ci95;
        assert!(
            lo <= r.contained_share && r.contained_share <= hi && lo > 0.9,
            "{lo} {hi}"
        );
        assert_eq!(count, [1, 1]);
        let partly = draw(&mut rng, 0.6);
        let (rows, count) = score_rows(&m, &[partly], &vec![1.0; 500], 1, &s);
        assert_eq!(rows[0].containment, Verdict::NotContained, "seed {seed}");
        assert_eq!(count, [0, 0]);
    }
}

/// The same ensemble at two seeds: no row is decided contained at one and not contained at the
/// other, and the counts' intervals overlap (the truth of the bundled data set, and a wrong μc).
#[test]
fn containment_verdicts_do_not_contradict_each_other_across_seeds() {
    let m = fixture();
    let s = ScoreSettings::default();
    for spec in [
        SyntheticDesign::default().truth,
        truth_with("mu_c=normal:0.8:0.08"),
    ] {
        let run = |seed: u64| pinfeed::validate::validate(&m, &spec, seed, 300, 1, &s).unwrap();
        let (a, sa, _) = run(1);
        let (b, sb, _) = run(2);
        for (x, y) in a.iter().zip(&b) {
            assert!(
                !matches!(
                    (x.containment, y.containment),
                    (Verdict::Contained, Verdict::NotContained)
                        | (Verdict::NotContained, Verdict::Contained)
                ),
                "line {}: {:?} {:?} at seed 1, {:?} {:?} at seed 2",
                x.line,
                x.containment,
                x.contained_share_ci95,
                y.containment,
                y.contained_share_ci95
            );
        }
        assert!(
            sa.contained_ci95[0] <= sb.contained_ci95[1]
                && sb.contained_ci95[0] <= sa.contained_ci95[1],
            "{sa:?} {sb:?}"
        );
        assert!(sa.verdict_undecided < sa.rows / 2, "{sa:?}");
    }
}

/// Rows at the same d and input (a thesis-style table) use one prediction.
#[test]
fn rows_at_the_same_d_share_one_prediction() {
    let m = measured::load(Path::new("tests/fixtures/validate/table_example.csv"), 0.0).unwrap();
    let spec = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
        .with_settings("mu_c=normal:0.5:0.1,jitter=2")
        .unwrap();
    let (rows, _, pred) =
        pinfeed::validate::validate(&m, &spec, 1, 40, 1, &ScoreSettings::default()).unwrap();
    for (i, a) in rows.iter().enumerate() {
        for (j, b) in rows.iter().enumerate() {
            if a.d == b.d {
                assert_eq!(
                    pred.rows[i], pred.rows[j],
                    "lines {} and {}",
                    a.line, b.line
                );
                assert_eq!(a.predicted, b.predicted);
            } else {
                assert_ne!(pred.rows[i], pred.rows[j]);
            }
        }
    }
}

/// A calibration whose best grid point gives the members of one support group weights of order
/// 1e-200 (10 members, μc range 0:10): their squares underflowed and the effective member count
/// was 0/0, printed as `null`. It is finite now, between 1 and the member count.
#[test]
fn calibration_effective_members_stay_finite_when_weights_underflow() {
    let text = "part,d,input,min_deg,max_deg,trials\ntripoly1,-0.7,state:0,355.1,5.9,20\ntripoly1,-0.7,state:1,129.2,142.5,20\ntripoly1,-0.7,state:2,219.4,229.7,20\n";
    let m = measured::parse(Path::new("m.csv"), text, 0.5).unwrap();
    let s = CalibrationSettings {
        members: 10,
        mu_c_range: (0.0, 10.0),
        ..CalibrationSettings::default()
    };
    let cal = calibrate(&m, &s).unwrap();
    assert!(
        cal.effective_members.is_finite()
            && cal.effective_members >= 1.0 - 1e-9
            && cal.effective_members <= 10.0 + 1e-9,
        "{}",
        cal.effective_members
    );
    assert!(cal.log_likelihood.is_finite());
}
