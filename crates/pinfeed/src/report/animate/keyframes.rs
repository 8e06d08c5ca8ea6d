//! A part's keyframes: world poses turned into SVG poses (θ unwrapped), clipped to the shown span
//! and thinned (Douglas–Peucker in time) to at most [`MAX_KEYS`]; a pin's track thinned alike.

use super::layout::Layout;
use super::model::{MAX_KEYS, POSE_TOLERANCE_PX};
use crate::geometry::{wrap_pi, Pose};

/// One keyframe of a part: key time and the SVG pose (px, px, degrees).
#[derive(Debug, Clone, Copy)]
pub(super) struct Key {
    pub(super) t: f64,
    pub(super) x: f64,
    pub(super) y: f64,
    pub(super) deg: f64,
}

pub(super) fn lerp_key(a: &Key, b: &Key, t: f64) -> Key {
    let w = if b.t > a.t {
        ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Key {
        t,
        x: a.x + w * (b.x - a.x),
        y: a.y + w * (b.y - a.y),
        deg: a.deg + w * (b.deg - a.deg),
    }
}

/// The part's keyframes in SVG terms: θ unwrapped (consecutive turns within ±180°), clipped to
/// [t0, t1]; non-finite poses are skipped.
pub(super) fn part_keys(lay: &Layout, poses: &[(f64, Pose)], t0: f64, t1: f64) -> Vec<Key> {
    let mut keys: Vec<Key> = Vec::new();
    let mut prev_theta: Option<(f64, f64)> = None; // (raw, unwrapped)
    for &(t, p) in poses {
        if !(t.is_finite() && p.x.is_finite() && p.y.is_finite() && p.theta_rad.is_finite()) {
            continue;
        }
        let theta = match prev_theta {
            Some((raw, unwrapped)) => unwrapped + wrap_pi(p.theta_rad - raw),
            None => p.theta_rad,
        };
        prev_theta = Some((p.theta_rad, theta));
        // Keep times in order (a recorded path is; guard against a bad one).
        let t = keys.last().map_or(t, |k| t.max(k.t));
        keys.push(Key {
            t,
            x: lay.x(p.x),
            y: lay.y(p.y),
            deg: -theta.to_degrees(),
        });
    }
    clip_keys(keys, t0, t1)
}

/// Keep the keys within [t0, t1], interpolating new ends where the path crosses them.
pub(super) fn clip_keys(keys: Vec<Key>, t0: f64, t1: f64) -> Vec<Key> {
    if keys.is_empty() || keys[keys.len() - 1].t < t0 || keys[0].t > t1 {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(keys.len());
    for i in 0..keys.len() {
        let k = keys[i];
        if k.t < t0 {
            if let Some(n) = keys.get(i + 1) {
                if n.t > t0 {
                    out.push(lerp_key(&k, n, t0));
                }
            }
            continue;
        }
        if k.t > t1 {
            if i > 0 && keys[i - 1].t < t1 {
                out.push(lerp_key(&keys[i - 1], &k, t1));
            }
            break;
        }
        out.push(k);
    }
    out
}

/// Greatest drawing error (px) of replacing keys a..=b by the straight interpolation a → b.
pub(super) fn worst(keys: &[Key], a: usize, b: usize, arm_px: f64) -> (f64, usize) {
    let mut worst = (0.0, a);
    for (i, k) in keys.iter().enumerate().take(b).skip(a + 1) {
        let m = lerp_key(&keys[a], &keys[b], k.t);
        let e = (m.x - k.x)
            .abs()
            .max((m.y - k.y).abs())
            .max((m.deg - k.deg).abs().to_radians() * arm_px);
        if e > worst.0 {
            worst = (e, i);
        }
    }
    worst
}

/// Douglas–Peucker in time: the fewest keys whose linear interpolation stays within `tol` px
/// (position, and rotation measured at the outline's radius `arm_px`) of every recorded key.
pub(super) fn simplify(keys: &[Key], tol: f64, arm_px: f64) -> Vec<Key> {
    if keys.len() <= 2 {
        return keys.to_vec();
    }
    let mut keep = vec![false; keys.len()];
    keep[0] = true;
    keep[keys.len() - 1] = true;
    let mut stack = vec![(0, keys.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (e, i) = worst(keys, a, b, arm_px);
        if e > tol {
            keep[i] = true;
            stack.push((a, i));
            stack.push((i, b));
        }
    }
    keys.iter()
        .zip(keep)
        .filter(|(_, k)| *k)
        .map(|(k, _)| *k)
        .collect()
}

/// Thin keys to at most [`MAX_KEYS`], loosening the tolerance as needed.
pub(super) fn thin(keys: &[Key], arm_px: f64) -> Vec<Key> {
    let mut tol = POSE_TOLERANCE_PX;
    loop {
        let out = simplify(keys, tol, arm_px);
        if out.len() <= MAX_KEYS || tol > 1e6 {
            if out.len() <= MAX_KEYS {
                return out;
            }
            // Degenerate input: sample evenly.
            let n = out.len();
            return (0..MAX_KEYS)
                .map(|i| out[i * (n - 1) / (MAX_KEYS - 1)])
                .collect();
        }
        tol *= 2.0;
    }
}

/// Thin a pin's (t, y) knots to at most [`MAX_KEYS`] (Douglas–Peucker, as for parts).
pub(super) fn thin_track(pts: &[(f64, f64)], lay: &Layout) -> Vec<(f64, f64)> {
    let keys: Vec<Key> = pts
        .iter()
        .map(|&(t, y)| Key {
            t,
            x: 0.0,
            y: y * lay.k,
            deg: 0.0,
        })
        .collect();
    thin(&keys, 0.0)
        .iter()
        .map(|k| (k.t, k.y / lay.k))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec2;
    use crate::report::animate::model::Animation;

    #[test]
    fn simplify_keeps_corners_and_drops_straight_runs() {
        let mut keys = Vec::new();
        for i in 0..=100 {
            let t = i as f64;
            // Straight to t = 50, then a turn in place.
            let (x, deg) = if i <= 50 { (t, 0.0) } else { (50.0, t - 50.0) };
            keys.push(Key { t, x, y: 0.0, deg });
        }
        let out = simplify(&keys, 0.3, 10.0);
        assert_eq!(out.len(), 3, "{out:?}");
        assert_eq!(out[1].t, 50.0);
    }

    #[test]
    fn thin_caps_the_number_of_keys() {
        let keys: Vec<Key> = (0..5000)
            .map(|i| Key {
                t: i as f64,
                x: (i as f64 * 0.7).sin() * 50.0,
                y: 0.0,
                deg: 0.0,
            })
            .collect();
        assert!(thin(&keys, 1.0).len() <= MAX_KEYS);
    }

    #[test]
    fn clipping_interpolates_the_ends() {
        let keys = vec![
            Key {
                t: 0.0,
                x: 0.0,
                y: 0.0,
                deg: 0.0,
            },
            Key {
                t: 10.0,
                x: 10.0,
                y: 0.0,
                deg: 0.0,
            },
        ];
        let out = clip_keys(keys, 2.0, 5.0);
        assert_eq!(out.len(), 2);
        assert_eq!((out[0].t, out[0].x), (2.0, 2.0));
        assert_eq!((out[1].t, out[1].x), (5.0, 5.0));
    }

    /// The layout of a 10 s animation of a belt 0.1 m wide, with no obstacles or parts.
    fn layout(belt_length: f64, belt_speed: f64, outline: Vec<Vec2>) -> Layout {
        let anim = Animation {
            title: String::new(),
            belt_length,
            belt_width: 0.1,
            belt_speed,
            outline,
            obstacles: vec![],
            parts: vec![],
            marks: vec![],
            t_start: 0.0,
            t_end: 10.0,
        };
        Layout::new(&anim, 10.0)
    }

    #[test]
    fn theta_is_unwrapped() {
        let lay = layout(1.0, 0.1, vec![]);
        let poses = [
            (0.0, Pose::new(0.0, 0.0, 6.2)),
            (1.0, Pose::new(0.0, 0.0, 0.1)),
        ];
        let keys = part_keys(&lay, &poses, 0.0, 10.0);
        let turn = keys[1].deg - keys[0].deg;
        assert!(turn.abs() < 20.0, "turned {turn}°");
    }

    /// The drawing's transform — translate to the key's centre, rotate by its angle, outline at
    /// (k x, −k y) — puts every vertex where the world pose puts it (so parts turn about their
    /// centroid, to scale, and the right way round).
    #[test]
    fn keys_place_the_outline_like_the_world_pose() {
        let outline = vec![
            Vec2::new(-0.01, -0.005),
            Vec2::new(0.02, -0.005),
            Vec2::new(-0.01, 0.01),
        ];
        let lay = layout(0.6, 0.05, outline.clone());
        let pose = Pose::new(0.2, -0.01, 0.7);
        let keys = part_keys(&lay, &[(1.0, pose)], 0.0, 10.0);
        let k = keys[0];
        let (s, c) = crate::geometry::sin_cos(k.deg.to_radians());
        for v in &outline {
            let (lx, ly) = (v.x * lay.k, -v.y * lay.k);
            // SVG rotate(a): (x cos a − y sin a, x sin a + y cos a).
            let (sx, sy) = (k.x + lx * c - ly * s, k.y + lx * s + ly * c);
            let w = pose.apply(*v);
            assert!((sx - lay.x(w.x)).abs() < 1e-9 && (sy - lay.y(w.y)).abs() < 1e-9);
        }
    }
}
