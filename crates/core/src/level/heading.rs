//! Headings in the horizontal plane, shared by both games: degrees about +Y, heading `h`
//! pointing along `(cos h, 0, −sin h)`, so a positive angle turns left seen from above.

/// The horizontal unit direction `[x, z]` of a heading in degrees.
pub fn heading_direction(heading_degrees: f64) -> [f64; 2] {
    let h = heading_degrees.to_radians();
    [h.cos(), -h.sin()]
}

/// The heading, in degrees, of the horizontal direction `[x, z]`.
pub fn direction_heading(x: f64, z: f64) -> f64 {
    (-z).atan2(x).to_degrees()
}

/// Wraps an angle in degrees into (-180, 180].
pub fn wrap_degrees(angle: f64) -> f64 {
    let wrapped = angle.rem_euclid(360.0);
    if wrapped > 180.0 {
        wrapped - 360.0
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_wrap_and_convert_both_ways() {
        assert_eq!(wrap_degrees(270.0), -90.0);
        assert_eq!(wrap_degrees(-180.0), 180.0);
        for h in [-135.0, -30.0, 0.0, 45.0, 170.0] {
            let [x, z] = heading_direction(h);
            assert!((direction_heading(x, z) - h).abs() < 1e-9);
        }
    }
}
