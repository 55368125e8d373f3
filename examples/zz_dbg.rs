use glam::DVec3;
use tessera::tiling::sphere::SphereTiling;
use tessera::tiling::TileSystem;
use tessera::Sampler;
fn main() {
    let n: usize = std::env::args().nth(1).unwrap().parse().unwrap();
    let t = SphereTiling::default();
    let lut = t.lut();
    let level = (0..).find(|&l| t.capacity(l) >= n as f64).unwrap();
    let cap = t.capacity(level);
    let f = n as f64 / cap;
    let bin = lut.bin(f, cap);
    let mut tiles = t.tiles(level);
    tiles.sort_by_key(|x| x.code);
    let pts: Vec<DVec3> = Sampler::sphere()
        .count(n)
        .generate()
        .unwrap()
        .iter()
        .map(|s| s.position)
        .collect();
    let mine: Vec<DVec3> = tiles[..n].iter().map(|x| t.sample(x, f)).collect();
    let same = pts
        .iter()
        .zip(&mine)
        .filter(|(a, b)| a.angle_between(**b) < 1e-9)
        .count();
    println!("level {level} bin {bin} same {same}/{n}");
    let mut best = (f64::INFINITY, 0, 0);
    for i in 0..n {
        for j in i + 1..n {
            let d = mine[i].angle_between(mine[j]);
            if d < best.0 {
                best = (d, i, j);
            }
        }
    }
    let (d, i, j) = best;
    let pc = cap / 4.0;
    for k in [i, j] {
        let x = &tiles[k];
        println!(
            "code {} parent {} digit {} index {} fill {:?} offset {:?} bin offset {:?}",
            x.code,
            x.code as f64 % pc,
            (x.code as f64 / pc).floor(),
            x.index,
            lut.fill_pair(x.code, level, f, bin, cap),
            t.offset(x, f),
            lut.offset(level as usize, x.index as usize, bin)
        );
    }
    println!("min dist * sqrt(n) = {}", d * (n as f64).sqrt());
}
