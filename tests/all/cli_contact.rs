//! `pinfeed contact` through the binary: JSON fields, trace and plot files, batch CSV, bad input.

use crate::support::{pinfeed, pinfeed_json};

/// The JSON object carries the documented keys with sensible values, for every model.
#[test]
fn json_has_required_fields() {
    for model in ["exact", "ellipsoid", "tip"] {
        let v = pinfeed_json(&[
            "contact", "--part", "tripoly2", "--theta0", "90", "--d", "0.3", "--model", model,
            "--json",
        ]);
        for key in [
            "contact",
            "theta_final_deg",
            "rotation_deg",
            "com_final",
            "contact_length",
            "segments",
            "evaluations",
            "status",
        ] {
            assert!(v.get(key).is_some(), "{model}: missing {key}");
        }
        assert_eq!(v["contact"], true);
        assert_eq!(v["status"], "ok");
        let th = v["theta_final_deg"].as_f64().unwrap();
        assert!((0.0..360.0).contains(&th));
        let rot = v["rotation_deg"].as_f64().unwrap();
        assert!(((90.0 + rot).rem_euclid(360.0) - th).abs() < 1e-9);
        assert!(
            v["rotation_deg"].as_f64().unwrap() > 0.0,
            "pushed above the centroid turns CCW"
        );
        assert!(v["evaluations"].as_u64().unwrap() > 0);
        assert_eq!(v["com_final"].as_array().unwrap().len(), 2);
        assert!(!v["segments"].as_array().unwrap().is_empty());
    }
}

/// A pin that passes the part reports no contact and an unchanged orientation.
#[test]
fn miss_reports_no_contact() {
    let v = pinfeed_json(&[
        "contact", "--part", "square", "--theta0", "0", "--d", "0.9", "--json",
    ]);
    assert_eq!(v["contact"], false);
    assert_eq!(v["theta_final_deg"].as_f64().unwrap(), 0.0);
    assert_eq!(v["contact_length"].as_f64().unwrap(), 0.0);
}

/// Negative angles and offsets parse; trace and plot files are written.
#[test]
fn trace_and_plot_files() {
    let dir = std::env::temp_dir().join(format!("pinfeed-cli-contact-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("t.csv");
    let plot = dir.join("p.svg");
    let out = pinfeed(&[
        "contact",
        "--part",
        "tripoly1",
        "--theta0",
        "-20",
        "--d",
        "-0.25",
        "--model",
        "ellipsoid",
        "--trace",
        trace.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(&trace).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("s,x,y,theta_deg"));
    assert!(
        header.ends_with("normal_x,normal_y,rotation_rate"),
        "{header}"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            let cols: Vec<&str> = l.split(',').collect();
            assert_eq!(cols.len(), 16, "{l}");
            [8, 9, 13, 14, 15]
                .iter()
                .map(|&i| cols[i].parse().unwrap())
                .collect()
        })
        .collect();
    assert!(rows.len() >= 3, "a contact has several recorded steps");
    for r in &rows {
        // The normal is a unit vector, and the force presses along it: f·n > 0.
        assert!((r[2].hypot(r[3]) - 1.0).abs() < 1e-12, "{r:?}");
        assert!(r[0] * r[2] + r[1] * r[3] > 0.0, "{r:?}");
    }
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.contains("<svg") && svg.len() > 1000);
}

/// The strokes of the polylines drawn in `colour` (plotters' SVG: `stroke="#RRGGBB"`), as point
/// lists.
fn polylines_in(svg: &str, colour: &str) -> Vec<Vec<(f64, f64)>> {
    svg.lines()
        .filter(|l| l.starts_with("<polyline") && l.contains(&format!("stroke=\"{colour}\"")))
        .map(|l| {
            let points = l
                .split("points=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            points
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect()
}

/// `--fence ... --plot` draws the fence (at the start and end of contact) and no pin; a pin pass
/// draws no fence.
#[test]
fn fence_plot_draws_the_fence() {
    let dir = std::env::temp_dir().join(format!("pinfeed-cli-fence-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fence_colour = {
        let c = pinfeed::report::plot_contact::FENCE_COLOUR;
        format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
    };
    let draw = |extra: &[&str], file: &str| -> String {
        let plot = dir.join(file);
        let mut args = vec![
            "contact", "--part", "tripoly2", "--theta0", "30", "--d", "0.1", "--plot",
        ];
        args.push(plot.to_str().unwrap());
        args.extend_from_slice(extra);
        let out = pinfeed(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read_to_string(&plot).unwrap()
    };
    let svg = draw(&["--fence", "30"], "fence.svg");
    assert!(svg.contains("fence α=30°"), "the title names the fence");
    let fences = polylines_in(&svg, &fence_colour);
    assert_eq!(fences.len(), 2, "the fence at the start and end of contact");
    for f in &fences {
        assert_eq!(f.len(), 2, "a fence is one segment: {f:?}");
        let (dx, dy) = (f[1].0 - f[0].0, f[1].1 - f[0].1);
        assert!(dx.hypot(dy) > 0.0, "{f:?}");
        // Drawn at the fence's angle: 30° from the belt direction (SVG y points down).
        assert!(((-dy).atan2(dx).to_degrees() - 30.0).abs() < 5.0, "{f:?}");
    }
    assert!(
        polylines_in(&svg, "#FF0000").is_empty() && !svg.contains("fill=\"#FF0000\""),
        "a fence pass draws no pin"
    );
    let pin = draw(&[], "pin.svg");
    assert!(polylines_in(&pin, &fence_colour).is_empty());
    assert!(!polylines_in(&pin, "#FF0000").is_empty(), "the pin's path");
}

/// Batch mode: one output row per case, in order, with the same physics as single runs.
#[test]
fn batch_cases_csv() {
    let dir = std::env::temp_dir().join(format!("pinfeed-cli-batch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = dir.join("cases.csv");
    std::fs::write(
        &cases,
        "part,theta0,d,mu_c,model\ntripoly2,90,0.3,0.5,ellipsoid\ntripoly1,10,-0.2,0.2,tip\nsquare,0,0.9,0.5,\n",
    )
    .unwrap();
    let out = pinfeed(&["contact", "--cases", cases.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<&str> = text.lines().collect();
    assert_eq!(rows.len(), 4, "{text}");
    assert!(rows[0].starts_with("part,theta0,d,mu_c,model"));
    assert!(rows[1].starts_with("tripoly2,90.0,0.3,0.5,ellipsoid"));
    assert!(
        rows[3].contains(",false,"),
        "square at d=0.9 misses: {}",
        rows[3]
    );
    // Same numbers as the single-case command.
    let single = pinfeed_json(&[
        "contact",
        "--part",
        "tripoly2",
        "--theta0",
        "90",
        "--d",
        "0.3",
        "--model",
        "ellipsoid",
        "--json",
    ]);
    let th = single["theta_final_deg"].as_f64().unwrap();
    let field: f64 = rows[1].split(',').nth(8).unwrap().parse().unwrap();
    assert_eq!(field, th);
}

/// Bad batch rows name the file and line.
#[test]
fn batch_errors_name_the_line() {
    let dir = std::env::temp_dir().join(format!("pinfeed-cli-batchbad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = dir.join("bad.csv");
    std::fs::write(
        &cases,
        "part,theta0,d,mu_c\ntripoly2,90,0.3,0.5\ntripoly2,abc,0.3,0.5\n",
    )
    .unwrap();
    let out = pinfeed(&["contact", "--cases", cases.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.csv:3"), "{err}");
    std::fs::write(&cases, "part,theta0,d,mu_c\ntripoly2,90,0.3,-1\n").unwrap();
    let out = pinfeed(&["contact", "--cases", cases.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.csv:2") && err.contains("column mu_c"),
        "{err}"
    );
    std::fs::write(
        &cases,
        "part,theta0,d,mu_c,colour\ntripoly2,90,0.3,0.5,red\n",
    )
    .unwrap();
    let out = pinfeed(&["contact", "--cases", cases.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("colour"));
}

/// Bad single-case input: clear message, non-zero exit, never a panic.
#[test]
fn bad_inputs_are_refused() {
    let base = [
        "contact", "--part", "tripoly2", "--theta0", "10", "--d", "0.2",
    ];
    let cases: &[(&[&str], &str)] = &[
        (&["--mu-c", "-0.5"], "mu-c"),
        (&["--mu-s", "0"], "mu-s"),
        (&["--pin-radius", "-1"], "pin-radius"),
        (&["--tol", "0"], "tol"),
        (&["--model", "quantum"], "unknown model"),
        (&["--support", "blob"], "unknown support"),
        (&["--mu-c", "NaN"], "finite"),
    ];
    for (extra, word) in cases {
        let mut args: Vec<&str> = base.to_vec();
        args.extend_from_slice(extra);
        let out = pinfeed(&args);
        assert!(!out.status.success(), "{extra:?} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(word), "{extra:?}: {err}");
        assert!(!err.contains("panicked"), "{extra:?}: {err}");
    }
    let out = pinfeed(&["contact", "--part", "blob", "--theta0", "0", "--d", "0"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown part"));
}

/// A random tripod support runs through the CLI (exact point sums).
#[test]
fn tripod_support_runs() {
    let v = pinfeed_json(&[
        "contact",
        "--part",
        "tripoly2",
        "--theta0",
        "200",
        "--d",
        "0.1",
        "--support",
        "tripod:3",
        "--json",
    ]);
    assert_eq!(v["status"], "ok");
}

/// `--pin-stop-after S`: a pin that stops at once is a still pin; one that stops after the whole
/// pass is the constant-speed moving pin; in between the stop changes the outcome.
#[test]
fn pin_stop_after_spans_still_and_moving_pins() {
    let th = |extra: &[&str]| -> f64 {
        let mut args = vec![
            "contact", "--part", "tripoly2", "--theta0", "40", "--d=-0.2", "--json",
        ];
        args.extend_from_slice(extra);
        pinfeed_json(&args)["theta_final_deg"].as_f64().unwrap()
    };
    let still = th(&[]);
    let moving = th(&["--pin-speed", "0.5"]);
    assert!(
        (still - moving).abs() > 1.0,
        "the lateral speed matters: {still} vs {moving}"
    );
    let at_once = th(&["--pin-speed", "0.5", "--pin-stop-after", "1e-9"]);
    assert!((at_once - still).abs() < 1e-6, "{at_once} vs {still}");
    let never = th(&["--pin-speed", "0.5", "--pin-stop-after", "100"]);
    assert!((never - moving).abs() < 1e-9, "{never} vs {moving}");
    let mid = th(&["--pin-speed", "0.5", "--pin-stop-after", "1.2"]);
    assert!(
        (mid - still).abs() > 1e-3 && (mid - moving).abs() > 1e-3,
        "{mid}"
    );
    let out = pinfeed(&[
        "contact",
        "--part",
        "tripoly2",
        "--theta0",
        "40",
        "--d=-0.2",
        "--pin-speed",
        "0.5",
        "--pin-stop-after=-1",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--pin-stop-after must be in"));
}
