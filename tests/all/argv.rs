//! proptest strategies for `pinfeed` argument vectors: numbers as a user might type them (and
//! awkward ones), part specifications, and whole `part`, `contact` and `map --no-write` argument
//! vectors built from the real flags, sometimes mutated. Shared by the integration tests (which
//! run them through the built binary) and the command line's own tests (in process).
#![allow(dead_code)]

use super::shapes;
use proptest::prelude::*;

/// A number as a user might type it, or something that only looks like one.
pub(crate) fn number() -> BoxedStrategy<String> {
    prop_oneof![
        3 => prop::sample::select(vec![
            "nan", "NaN", "inf", "-inf", "infinity", "0", "-0", "1e308", "-1e308", "5e-324",
            "-5e-324", "1e-300", "1e300", "1e6", "-1e6", "1e-13", "1e-12", "0.01", "10", "100",
            "1000", "-90", "90", "89.999", "abc", "", "1,2", "0x10", "1e", "--", "+1", ".5",
        ])
        .prop_map(String::from),
        4 => (-2.0f64..2.0).prop_map(|x| x.to_string()),
        2 => (-400.0f64..400.0).prop_map(|x| x.to_string()),
        3 => (-9.99f64..9.99, -320i32..309).prop_map(|(m, e)| format!("{m:.3}e{e}")),
    ]
    .boxed()
}

/// A star-shaped polygon about the origin (3–8 vertices, radii in [0.2, 1]).
pub(crate) fn star() -> impl Strategy<Value = Vec<(f64, f64)>> {
    shapes::star_polygon(3..9)
}

pub(crate) fn vertex_text(v: &[(f64, f64)]) -> String {
    v.iter()
        .map(|(x, y)| format!("{x:e},{y:e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A vertex list: a star polygon at a random magnitude, sometimes mutated (a vertex dropped,
/// repeated or swapped, a coordinate replaced by an awkward number).
pub(crate) fn vertex_list() -> BoxedStrategy<String> {
    (
        star(),
        prop_oneof![1 => -300i32..300, 3 => -60i32..60],
        prop_oneof![3 => Just(5usize), 1 => 0usize..5],
        any::<prop::sample::Index>(),
        number(),
    )
        .prop_map(|(v, e, mutation, at, num)| {
            let k = 10f64.powi(e);
            let mut words: Vec<String> = v
                .iter()
                .map(|&(x, y)| format!("{:e},{:e}", x * k, y * k))
                .collect();
            let i = at.index(words.len());
            match mutation {
                0 => {
                    words.remove(i);
                }
                1 => {
                    let w = words[i].clone();
                    words.insert(i, w);
                }
                2 => words.swap(i, (i + 1) % v.len()),
                3 => {
                    let y = words[i].split(',').nth(1).unwrap().to_string();
                    words[i] = format!("{num},{y}");
                }
                _ => {}
            }
            words.join(" ")
        })
        .boxed()
}

/// A part specification: a named part (with random parameters) or a vertex list.
pub(crate) fn part_spec() -> BoxedStrategy<String> {
    prop_oneof![
        1 => prop::sample::select(vec!["tripoly1", "tripoly2", "square", "lshape", "blob", ""])
            .prop_map(String::from),
        1 => (number(), number()).prop_map(|(w, h)| format!("rect:{w}:{h}")),
        1 => prop_oneof![Just("3".to_string()), Just("7".to_string()), number()]
            .prop_map(|n| format!("ngon:{n}")),
        3 => vertex_list().prop_map(|v| format!("vertices:{v}")),
    ]
    .boxed()
}

/// A flag and the range its plausible values are drawn from (log-uniform when `log`).
pub(crate) type FlagRange = (&'static str, f64, f64, bool);

/// Optional `--flag=value` words: each flag present with probability 0.4, its value mostly drawn
/// from the flag's plausible range, sometimes any number.
pub(crate) fn optional_flags(flags: &'static [FlagRange]) -> BoxedStrategy<Vec<String>> {
    prop::collection::vec(
        (
            prop::bool::weighted(0.4),
            0.0f64..1.0,
            number(),
            prop::bool::weighted(0.8),
        ),
        flags.len(),
    )
    .prop_map(move |vals| {
        flags
            .iter()
            .zip(vals)
            .filter(|(_, (on, ..))| *on)
            .map(|(&(f, lo, hi, log), (_, u, any, plausible))| {
                let v = if !plausible {
                    any
                } else if log {
                    format!(
                        "{:e}",
                        10f64.powf(lo.log10() + u * (hi.log10() - lo.log10()))
                    )
                } else if f == "threads" {
                    ((lo + u * (hi - lo)) as usize).to_string()
                } else {
                    (lo + u * (hi - lo)).to_string()
                };
                format!("--{f}={v}")
            })
            .collect()
    })
    .boxed()
}

pub(crate) fn model() -> impl Strategy<Value = Vec<String>> {
    prop::option::of(prop::sample::select(vec![
        "exact",
        "ellipsoid",
        "tip",
        "quantum",
    ]))
    .prop_map(|m| m.map(|m| vec![format!("--model={m}")]).unwrap_or_default())
}

pub(crate) fn support() -> impl Strategy<Value = Vec<String>> {
    prop::option::of(prop_oneof![
        Just("uniform".to_string()),
        (0u64..1000).prop_map(|s| format!("tripod:{s}")),
        number().prop_map(|s| format!("tripod:{s}")),
    ])
    .prop_map(|s| {
        s.map(|s| vec![format!("--support={s}")])
            .unwrap_or_default()
    })
}

pub(crate) fn fence() -> impl Strategy<Value = Vec<String>> {
    prop::option::weighted(
        0.25,
        prop_oneof![
            (-89.0f64..89.0).prop_map(|a| format!("{a}")),
            (-89.0f64..89.0, number()).prop_map(|(a, l)| format!("{a}:{l}")),
            (number(), number()).prop_map(|(a, l)| format!("{a}:{l}")),
        ],
    )
    .prop_map(|f| f.map(|f| vec![format!("--fence={f}")]).unwrap_or_default())
}

/// Drop, repeat or swap one word after the sub-command (or leave the vector alone).
pub(crate) fn mutate(mut args: Vec<String>, how: usize, at: prop::sample::Index) -> Vec<String> {
    if args.len() < 2 {
        return args;
    }
    let i = 1 + at.index(args.len() - 1);
    match how {
        0 => {
            args.remove(i);
        }
        1 => {
            let w = args[i].clone();
            args.insert(i, w);
        }
        2 if i + 1 < args.len() => args.swap(i, i + 1),
        _ => {}
    }
    args
}

/// `part` argument vectors.
pub(crate) fn part_args() -> BoxedStrategy<Vec<String>> {
    (
        part_spec(),
        any::<bool>(),
        0usize..6,
        any::<prop::sample::Index>(),
    )
        .prop_map(|(spec, by_vertices, how, at)| {
            let mut a = vec!["part".to_string()];
            match spec.strip_prefix("vertices:") {
                Some(v) if by_vertices => a.push(format!("--vertices={v}")),
                _ => a.push(spec),
            }
            a.push("--json".into());
            mutate(a, how, at)
        })
        .boxed()
}

/// Contact parameters mostly where pins touch, sometimes anywhere.
pub(crate) fn contact_d() -> BoxedStrategy<String> {
    prop_oneof![3 => (-1.1f64..1.1).prop_map(|d| d.to_string()), 1 => number()].boxed()
}

/// `contact` argument vectors (always `--json`).
pub(crate) fn contact_args() -> BoxedStrategy<Vec<String>> {
    (
        part_spec(),
        prop_oneof![3 => (-720.0f64..720.0).prop_map(|t| t.to_string()), 1 => number()],
        contact_d(),
        optional_flags(&[
            ("mu-c", 0.0, 2.0, false),
            ("mu-s", 0.01, 2.0, false),
            ("pin-radius", 0.0, 0.5, false),
            ("pin-speed", -1.0, 1.0, false),
            ("tol", 1e-9, 1e-3, true),
        ]),
        (model(), support(), fence()),
        (0usize..12, any::<prop::sample::Index>()),
    )
        .prop_map(|(part, theta0, d, flags, (m, s, f), (how, at))| {
            let mut a: Vec<String> = vec![
                "contact".into(),
                format!("--part={part}"),
                format!("--theta0={theta0}"),
                format!("--d={d}"),
                "--json".into(),
            ];
            a.extend(flags);
            a.extend(m);
            a.extend(s);
            a.extend(f);
            mutate(a, how, at)
        })
        .boxed()
}

/// `map --no-write --csv` argument vectors on small grids (at most 36 θ0 per map).
pub(crate) fn map_args() -> BoxedStrategy<Vec<String>> {
    (
        part_spec(),
        prop::collection::vec(contact_d(), 1..3),
        prop_oneof![
            3 => prop::sample::select(vec!["10", "15", "30", "45", "90", "120", "360"])
                .prop_map(String::from),
            // Not a valid step in [1e-4°, 0.5°): that asks for 7·10² to 3.6·10⁶ contacts
            // (the most one command allows), bounded work but minutes of it at --tol 1e-8 — a CI
            // run once spent 330 s on one such draw. Finer steps are refused (too many contacts)
            // and stay in.
            1 => number().prop_filter("a valid but slow θ step", |s| {
                !matches!(s.trim().parse::<f64>(), Ok(x) if (1e-4..0.5).contains(&x))
            }),
        ],
        optional_flags(&[
            ("mu-c", 0.0, 2.0, false),
            ("pin-radius", 0.0, 0.5, false),
            ("tol", 1e-8, 1e-3, true),
            ("threshold", 0.5, 30.0, false),
            ("threads", 1.0, 3.0, false),
        ]),
        (model(), support(), fence()),
        (0usize..12, any::<prop::sample::Index>()),
    )
        .prop_map(|(part, ds, step, flags, (m, s, f), (how, at))| {
            let mut a: Vec<String> = vec![
                "map".into(),
                format!("--part={part}"),
                format!("--theta-step={step}"),
                "--no-write".into(),
                "--csv".into(),
            ];
            if f.is_empty() {
                a.push(format!("--d={}", ds.join(",")));
                a.extend(flags);
            } else {
                // A fence map takes neither --d nor --pin-radius.
                a.extend(flags.into_iter().filter(|w| !w.starts_with("--pin-radius")));
                a.extend(f);
            }
            a.extend(m);
            a.extend(s);
            // Mutations must not drop --no-write (the command would write a report directory).
            let mut a = mutate(a, how, at);
            if !a.iter().any(|w| w == "--no-write") {
                a.push("--no-write".into());
            }
            a
        })
        .boxed()
}
