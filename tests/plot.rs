//! Pictures: PNGs decode at the right size and points land in the right pixels.

use glam::{DVec2, DVec3};
use tessera::density::rectangle::Rectangle;
use tessera::plot::{
    equirectangular, line_plot, log_image, orthographic, stipple, Axes, Labels, Marker, Series,
    MAX_STIPPLE_SIDE, PALETTE,
};

#[test]
fn stipple_places_points_y_down_as_images() {
    let img = stipple(
        &[DVec2::new(0.0, 0.0), DVec2::new(0.999, 0.999)],
        Rectangle::UNIT,
        50,
    )
    .unwrap();
    assert_eq!(img.dimensions(), (50, 50));
    assert_eq!(img.get_pixel(0, 0)[0], 0);
    assert_eq!(img.get_pixel(49, 49)[0], 0);
    // 1250 pixels per point: 3x3 dots, the rest white
    assert_eq!(img.pixels().filter(|p| p[0] == 0).count(), 2 * 4);
}

#[test]
fn stipple_maps_its_domain_onto_the_image() {
    let domain = Rectangle::new(-1.0, 2.0, 3.0, 4.0).unwrap();
    let points = [
        DVec2::new(-1.0, 2.0),
        DVec2::new(2.0, 2.5),
        DVec2::new(3.0, 4.0),
    ];
    let img = stipple(&points, domain, 400).unwrap();
    assert_eq!(img.dimensions(), (400, 200));
    for (col, row) in [(0, 0), (300, 50), (399, 199)] {
        assert_eq!(img.get_pixel(col, row)[0], 0, "({col}, {row})");
    }
    // 3x3 dots, the two in the corners clipped to 2x2
    assert_eq!(img.pixels().filter(|p| p[0] == 0).count(), 4 + 9 + 4);
}

#[test]
fn stipple_refuses_points_outside_its_domain_and_huge_images() {
    let outside = [DVec2::new(0.5, 0.5), DVec2::new(0.5, 1.25)];
    let e = stipple(&outside, Rectangle::UNIT, 64)
        .unwrap_err()
        .to_string();
    assert!(e.contains("point 2 (0.5, 1.25) lies outside"), "{e}");
    let nan = [DVec2::new(f64::NAN, 0.5)];
    let e = stipple(&nan, Rectangle::UNIT, 64).unwrap_err().to_string();
    assert!(e.contains("point 1 (NaN, 0.5) is not finite"), "{e}");
    let tall = Rectangle::new(0.0, 0.0, 1.0, 1e6).unwrap();
    let e = stipple(&[], tall, 64).unwrap_err().to_string();
    assert!(e.contains("pixels high"), "{e}");
    assert!(stipple(&[], Rectangle::UNIT, 0).is_err());
    assert!(stipple(&[], Rectangle::UNIT, MAX_STIPPLE_SIDE + 1).is_err());
}

#[test]
fn equirectangular_puts_directions_where_a_map_has_them() {
    let img = equirectangular(&[-DVec3::Y, -DVec3::Z], 360);
    assert_eq!(img.dimensions(), (360, 180));
    // -y: phi = atan2(-1, 0) mod 2 pi = 270 degrees, three quarters of the
    // width from the left, as a lat-long map's column
    assert_eq!(img.get_pixel(270, 90)[0], 0);
    assert_eq!(img.get_pixel(0, 179)[0], 0); // south pole, bottom row, phi 0
    assert_eq!(img.get_pixel(90, 90)[0], 255);
}

#[test]
fn orthographic_hides_the_far_hemisphere() {
    let img = orthographic(&[DVec3::Y, -DVec3::Z], 101, DVec3::Y);
    assert_eq!(img.get_pixel(50, 50)[0], 0);
    let seen = img.pixels().filter(|p| p[0] == 0).count();
    assert_eq!(seen, 9, "only +y is in front (a 3x3 dot)");
    // seen from +z, screen up is +x: +x sits at the top centre
    let near_x = DVec3::new(1.0, 0.0, 0.1).normalize();
    let top = orthographic(&[near_x], 101, DVec3::Z);
    assert_eq!(top.get_pixel(50, 0)[0], 0);
}

#[test]
fn log_image_orders_grey_levels_by_value() {
    let img = log_image(&[1.0, 10.0, 100.0, 1000.0], 2);
    let (a, b) = (img.get_pixel(0, 1)[0], img.get_pixel(1, 1)[0]);
    let (c, d) = (img.get_pixel(0, 0)[0], img.get_pixel(1, 0)[0]);
    assert!(a < b && b < c && c < d);
}

#[test]
fn line_plot_draws_each_series_and_roundtrips_through_png() {
    let rising = Series {
        points: (1..=10).map(|k| (k as f64, k as f64)).collect(),
        color: PALETTE[0],
        name: "rising".into(),
        marker: Marker::Square,
    };
    let falling = Series {
        points: (1..=10).map(|k| (k as f64, 1.0 / k as f64)).collect(),
        color: PALETTE[1],
        name: "falling".into(),
        marker: Marker::Cross,
    };
    let labels = Labels {
        title: "two lines".into(),
        x: "k".into(),
        y: "value".into(),
    };
    let img = line_plot(
        &[rising, falling],
        Axes {
            log_x: true,
            log_y: true,
        },
        &labels,
        300,
        200,
    );
    for color in &PALETTE[..2] {
        assert!(img.pixels().filter(|p| p.0 == *color).count() > 100);
    }
    let path = std::env::temp_dir().join(format!("tessera-plot-{}.png", std::process::id()));
    img.save(&path).unwrap();
    let back = image::open(&path).unwrap().to_rgb8();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(back, img);
}
