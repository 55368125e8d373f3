//! The offsets-off knob: `WithoutOffsets` samples at tile centroids, same codes.

use tessera::density::Uniform;
use tessera::engine;
use tessera::tiling::penrose::PenroseTiling;
use tessera::tiling::plane::PlaneTiling;
use tessera::tiling::reference::{ReferencePoint, WithoutOffsets};
use tessera::tiling::sphere::SphereTiling;
use tessera::tiling::TileSystem;

fn check<S: ReferencePoint + Clone>(system: S)
where
    S::Point: PartialEq + std::fmt::Debug,
    S::Region: tessera::density::Region<Point = S::Point>,
{
    let plain = WithoutOffsets(system.clone());
    let roots = system.roots();
    let mut moved = 0;
    for root in &roots {
        assert_eq!(plain.sample(root, 0.3), system.reference(root));
        assert_eq!(plain.code(root), system.code(root));
        moved += usize::from(system.sample(root, 1.0) != system.reference(root));
    }
    assert!(
        moved * 2 > roots.len(),
        "offsets move most samples off the centroid"
    );
    let a = engine::generate(&plain, &Uniform, 700, true).unwrap();
    let b = engine::generate(&system, &Uniform, 700, true).unwrap();
    assert_eq!(a.len(), 700);
    let ranks = |s: &[tessera::Sample<S::Point>]| s.iter().map(|x| x.rank).collect::<Vec<_>>();
    assert_eq!(
        ranks(&a),
        ranks(&b),
        "same tiles accepted in the same order"
    );
}

#[test]
fn without_offsets_keeps_codes_and_moves_samples_to_centroids() {
    check(SphereTiling::default());
    check(PlaneTiling::ghexomino());
    check(PlaneTiling::ppentomino());
}

#[test]
fn penrose_without_offsets_samples_point_tile_vertices_in_the_square() {
    let penrose = PenroseTiling::default();
    let plain = WithoutOffsets(penrose.clone());
    let a = engine::generate(&plain, &Uniform, 700, true).unwrap();
    let b = engine::generate(&penrose, &Uniform, 700, true).unwrap();
    assert_eq!(a.len(), 700);
    assert!(a
        .iter()
        .all(|s| s.position.cmpge(glam::DVec2::ZERO).all()
            && s.position.cmplt(glam::DVec2::ONE).all()));
    assert_ne!(a, b, "the offsets move the samples");
}
