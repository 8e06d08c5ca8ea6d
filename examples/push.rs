//! One push: a tripoly2 part (2 cm per unit) resting on the belt at θ0 = 30° is carried into a
//! fixed point pin at contact parameter d = −0.2 (the pin's offset from the centroid, in units of
//! the part's radius a). The contact model returns the final pose, the rotation and the segments of
//! the contact.
//!
//!     cargo run --release --example push

use pinfeed::geometry::part_from_spec;
use pinfeed::maps::pass_start;
use pinfeed::mechanics::{push, ContactSettings, PartModel, Pin, Support};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The part in metres, its weight spread uniformly over its footprint.
    let polygon = part_from_spec("tripoly2")?.scaled(0.02);
    let model = PartModel::new(&polygon, &Support::Uniform)?;

    // Where the part rests and where the pin starts, by the convention of every map and of
    // `pinfeed contact`: the centroid at the origin, the pin just clear of the part, at y = d·a.
    let (theta0_deg, d) = (30.0, -0.2);
    let (pose, pin_start) = pass_start(&polygon, theta0_deg, d, 0.0);

    let settings = ContactSettings::default(); // the exact model, μc 0.5
    let out = push(&model, pose, pin_start, &Pin::point(), &settings, None);

    println!(
        "tripoly2, θ0 = {theta0_deg}°, d = {d}, point pin, μc = {}",
        settings.mu_c
    );
    println!("status: {}", out.status.name());
    println!(
        "rotation: {:+.2}°, final orientation {:.2}°",
        out.rotation_rad.to_degrees(),
        pinfeed::geometry::wrap_deg(out.pose_final.theta_rad.to_degrees())
    );
    println!(
        "pin travel to contact {:.4} m, in contact over {:.4} m, {} segment(s)",
        out.travel_to_contact,
        out.contact_length,
        out.segments.len()
    );
    Ok(())
}
