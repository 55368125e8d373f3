//! Polyomino geometry: shapes made of unit cells, the 8 orientations of the
//! square lattice, placements, and rep-tile production rules.
//!
//! A point `p` in a tile's own frame (cell units) sits at `origin + T p` in the
//! lattice, with `T` one of the 8 orthogonal integer matrices. Children of a
//! `scale`-rep tile live on the lattice refined `scale` times.

pub mod exact_cover;

use serde::{Deserialize, Serialize};

/// A lattice coordinate. 64 bits keep deep levels exact: the sphere's
/// lattice at level `k` has `10 * 2^k` cells per face edge.
///
/// # Example
/// ```
/// let side: tessera::polyomino::Lattice = 10 << 40;
/// assert!(side > i32::MAX as i64);
/// ```
pub type Lattice = i64;

/// One of the 8 symmetries of the square lattice: `r` quarter turns
/// counter-clockwise applied after an optional mirror `x -> -x`.
///
/// # Example
/// ```
/// use tessera::polyomino::Orientation;
/// let quarter = Orientation::new(1, false);
/// assert_eq!(quarter.apply((1, 0)), (0, 1));
/// assert_eq!(quarter.then(quarter).then(quarter).then(quarter), Orientation::IDENTITY);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "u8")]
pub struct Orientation(u8);

/// Tables store orientations as their index; an index outside `0..8` (a
/// corrupt file) is refused when the table decodes, not met later.
///
/// # Example
/// ```
/// use tessera::polyomino::Orientation;
/// assert_eq!(Orientation::try_from(5).unwrap().index(), 5);
/// assert!(Orientation::try_from(8).is_err());
/// ```
impl TryFrom<u8> for Orientation {
    type Error = String;

    fn try_from(index: u8) -> Result<Self, String> {
        Orientation::ALL
            .get(index as usize)
            .copied()
            .ok_or_else(|| format!("orientation index {index} is not in 0..8"))
    }
}

impl Orientation {
    /// The identity.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::IDENTITY.apply((2, 3)), (2, 3));
    /// ```
    pub const IDENTITY: Orientation = Orientation(0);

    /// All 8 orientations, index order.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::ALL.len(), 8);
    /// ```
    pub const ALL: [Orientation; 8] = [
        Orientation(0),
        Orientation(1),
        Orientation(2),
        Orientation(3),
        Orientation(4),
        Orientation(5),
        Orientation(6),
        Orientation(7),
    ];

    /// `turns` quarter turns (mod 4) after an optional mirror.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::new(2, true).apply((1, 2)), (1, -2));
    /// ```
    pub fn new(turns: u8, mirrored: bool) -> Self {
        Orientation((turns % 4) | if mirrored { 4 } else { 0 })
    }

    /// Index in `0..8` (for tables).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::new(3, true).index(), 7);
    /// ```
    pub fn index(self) -> usize {
        self.0 as usize
    }

    /// The orientation with the given index (`index % 8`).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::from_index(5).index(), 5);
    /// ```
    pub fn from_index(index: usize) -> Self {
        Orientation((index % 8) as u8)
    }

    /// The integer matrix `[[a, b], [c, d]]` acting on column vectors.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::IDENTITY.matrix(), [[1, 0], [0, 1]]);
    /// ```
    pub fn matrix(self) -> [[Lattice; 2]; 2] {
        MATRICES[self.0 as usize]
    }

    /// Applies the orientation to an integer vector.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::new(0, true).apply((1, 1)), (-1, 1));
    /// ```
    pub fn apply(self, v: (Lattice, Lattice)) -> (Lattice, Lattice) {
        let m = self.matrix();
        (m[0][0] * v.0 + m[0][1] * v.1, m[1][0] * v.0 + m[1][1] * v.1)
    }

    /// Applies the orientation to a real vector.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// assert_eq!(Orientation::new(1, false).apply_f64([0.5, 0.0]), [0.0, 0.5]);
    /// ```
    #[inline]
    pub fn apply_f64(self, v: [f64; 2]) -> [f64; 2] {
        let m = &MATRICES_F64[self.0 as usize];
        [
            m[0][0] * v[0] + m[0][1] * v[1],
            m[1][0] * v[0] + m[1][1] * v[1],
        ]
    }

    /// The composition "first `self`, then `outer`" (matrix `outer * self`).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// let (a, b) = (Orientation::new(1, false), Orientation::new(0, true));
    /// assert_eq!(a.then(b).apply((1, 0)), b.apply(a.apply((1, 0))));
    /// ```
    pub fn then(self, outer: Orientation) -> Orientation {
        Orientation(COMPOSE[outer.0 as usize][self.0 as usize])
    }

    /// The inverse orientation.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Orientation;
    /// let o = Orientation::new(1, true);
    /// assert_eq!(o.then(o.inverse()), Orientation::IDENTITY);
    /// ```
    pub fn inverse(self) -> Orientation {
        Orientation(INVERSE[self.0 as usize])
    }
}

/// `rotation(turns) * diag(mirror, 1)` for every orientation index.
const MATRICES: [[[Lattice; 2]; 2]; 8] = {
    let mut out = [[[0; 2]; 2]; 8];
    let mut k = 0;
    while k < 8 {
        let mirror = if k & 4 != 0 { -1 } else { 1 };
        let (c, s) = match k & 3 {
            0 => (1, 0),
            1 => (0, 1),
            2 => (-1, 0),
            _ => (0, -1),
        };
        out[k] = [[c * mirror, -s], [s * mirror, c]];
        k += 1;
    }
    out
};

/// [`MATRICES`] in f64, for placing points without conversions.
const MATRICES_F64: [[[f64; 2]; 2]; 8] = {
    let mut out = [[[0.0; 2]; 2]; 8];
    let mut k = 0;
    while k < 8 {
        let m = MATRICES[k];
        out[k] = [
            [m[0][0] as f64, m[0][1] as f64],
            [m[1][0] as f64, m[1][1] as f64],
        ];
        k += 1;
    }
    out
};

/// `COMPOSE[a][b]`: the index of the matrix product `MATRICES[a] * MATRICES[b]`.
const COMPOSE: [[u8; 8]; 8] = {
    let mut out = [[0u8; 8]; 8];
    let mut a = 0;
    while a < 8 {
        let mut b = 0;
        while b < 8 {
            let (x, y) = (MATRICES[a], MATRICES[b]);
            let p = [
                [
                    x[0][0] * y[0][0] + x[0][1] * y[1][0],
                    x[0][0] * y[0][1] + x[0][1] * y[1][1],
                ],
                [
                    x[1][0] * y[0][0] + x[1][1] * y[1][0],
                    x[1][0] * y[0][1] + x[1][1] * y[1][1],
                ],
            ];
            let mut k = 0;
            while k < 8 {
                let m = MATRICES[k];
                if m[0][0] == p[0][0]
                    && m[0][1] == p[0][1]
                    && m[1][0] == p[1][0]
                    && m[1][1] == p[1][1]
                {
                    out[a][b] = k as u8;
                }
                k += 1;
            }
            b += 1;
        }
        a += 1;
    }
    out
};

/// `INVERSE[a]`: the index whose product with `a` is the identity.
const INVERSE: [u8; 8] = {
    let mut out = [0u8; 8];
    let mut a = 0;
    while a < 8 {
        let mut b = 0;
        while b < 8 {
            if COMPOSE[a][b] == 0 {
                out[a] = b as u8;
            }
            b += 1;
        }
        a += 1;
    }
    out
};

/// A polyomino: a finite set of unit cells given by their lower-left corners.
///
/// # Example
/// ```
/// use tessera::polyomino::Shape;
/// let p = Shape::p_pentomino();
/// assert_eq!(p.cells().len(), 5);
/// assert_eq!(p.bounding_size(), (2, 3));
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shape {
    cells: Vec<(Lattice, Lattice)>,
}

impl Shape {
    /// A shape from its cells (lower-left corners), kept in the given order.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::new(vec![(0, 0), (1, 0)]).cells().len(), 2);
    /// ```
    pub fn new(cells: Vec<(Lattice, Lattice)>) -> Self {
        Shape { cells }
    }

    /// The P-pentomino `XX / XX / X.` (a 2x2 block with one cell below its
    /// left column), as cells `(0,0) (0,1) (1,1) (0,2) (1,2)` with y up.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert!(Shape::p_pentomino().cells().contains(&(0, 0)));
    /// ```
    pub fn p_pentomino() -> Self {
        Shape::new(vec![(0, 0), (0, 1), (1, 1), (0, 2), (1, 2)])
    }

    /// The G-hexomino `X.. / XXX / XX.` (top row first), y up.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::g_hexomino().cells().len(), 6);
    /// ```
    pub fn g_hexomino() -> Self {
        Shape::new(vec![(0, 0), (1, 0), (0, 1), (1, 1), (2, 1), (0, 2)])
    }

    /// The cells, lower-left corners.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::p_pentomino().cells()[0], (0, 0));
    /// ```
    pub fn cells(&self) -> &[(Lattice, Lattice)] {
        &self.cells
    }

    /// Width and height of the bounding box in cells (assumes min corner 0).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::g_hexomino().bounding_size(), (3, 3));
    /// ```
    pub fn bounding_size(&self) -> (Lattice, Lattice) {
        let w = self.cells.iter().map(|c| c.0).max().unwrap_or(-1) + 1;
        let h = self.cells.iter().map(|c| c.1).max().unwrap_or(-1) + 1;
        (w, h)
    }

    /// The shape scaled by an integer factor (each cell becomes a block).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::p_pentomino().scaled(2).cells().len(), 20);
    /// ```
    pub fn scaled(&self, factor: Lattice) -> Shape {
        let mut cells = Vec::with_capacity(self.cells.len() * (factor * factor) as usize);
        for &(x, y) in &self.cells {
            for dy in 0..factor {
                for dx in 0..factor {
                    cells.push((x * factor + dx, y * factor + dy));
                }
            }
        }
        Shape::new(cells)
    }

    /// Centroid of the cells, in the shape's frame (cell units).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::new(vec![(0, 0), (1, 0)]).centroid(), [1.0, 0.5]);
    /// ```
    pub fn centroid(&self) -> [f64; 2] {
        let n = self.cells.len() as f64;
        let sx: f64 = self.cells.iter().map(|c| c.0 as f64 + 0.5).sum();
        let sy: f64 = self.cells.iter().map(|c| c.1 as f64 + 0.5).sum();
        [sx / n, sy / n]
    }

    /// Whether a point of the shape's frame lies in the closed shape.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// let p = Shape::p_pentomino();
    /// assert!(p.contains([0.5, 0.5]));
    /// assert!(!p.contains([1.5, 0.5]));
    /// ```
    pub fn contains(&self, p: [f64; 2]) -> bool {
        self.cells.iter().any(|&(x, y)| {
            p[0] >= x as f64 && p[0] <= x as f64 + 1.0 && p[1] >= y as f64 && p[1] <= y as f64 + 1.0
        })
    }

    /// The closest point of the shape, shrunk by `margin` cells, to `p`.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// let q = Shape::p_pentomino().clamp([1.7, 0.2], 0.01);
    /// assert!(Shape::p_pentomino().contains(q));
    /// ```
    pub fn clamp(&self, p: [f64; 2], margin: f64) -> [f64; 2] {
        let mut best = p;
        let mut best_d = f64::INFINITY;
        for &(x, y) in &self.cells {
            let q = [
                p[0].clamp(x as f64 + margin, x as f64 + 1.0 - margin),
                p[1].clamp(y as f64 + margin, y as f64 + 1.0 - margin),
            ];
            let d = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
            if d < best_d {
                best_d = d;
                best = q;
            }
        }
        best
    }
}

/// A copy of a shape on the lattice: shape-frame point `p` lies at
/// `origin + orientation * p`.
///
/// # Example
/// ```
/// use tessera::polyomino::{Orientation, Placement, Shape};
/// let p = Placement::new((5, 0), Orientation::new(1, false));
/// let cells: Vec<_> = p.cells(&Shape::new(vec![(0, 0), (1, 0)])).collect();
/// assert_eq!(cells, vec![(4, 0), (4, 1)]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Placement {
    /// Lattice point that the shape frame's origin maps to.
    pub origin: (Lattice, Lattice),
    /// Orientation of the copy.
    pub orientation: Orientation,
}

impl Placement {
    /// A placement from its origin and orientation.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::{Orientation, Placement};
    /// assert_eq!(Placement::new((1, 2), Orientation::IDENTITY).origin, (1, 2));
    /// ```
    pub fn new(origin: (Lattice, Lattice), orientation: Orientation) -> Self {
        Placement {
            origin,
            orientation,
        }
    }

    /// Lower-left corners of the lattice cells covered by `shape` so placed.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::{Orientation, Placement, Shape};
    /// let p = Placement::new((0, 0), Orientation::new(2, false));
    /// let cells: Vec<_> = p.cells(&Shape::new(vec![(0, 0)])).collect();
    /// assert_eq!(cells, vec![(-1, -1)]);
    /// ```
    pub fn cells<'a>(&self, shape: &'a Shape) -> impl Iterator<Item = (Lattice, Lattice)> + 'a {
        let (origin, orientation) = (self.origin, self.orientation);
        shape
            .cells()
            .iter()
            .map(move |&c| cell_image(origin, orientation, c))
    }

    /// Maps a shape-frame point to lattice coordinates.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::{Orientation, Placement};
    /// let p = Placement::new((2, 0), Orientation::new(1, false));
    /// assert_eq!(p.to_lattice([1.0, 0.5]), [1.5, 1.0]);
    /// ```
    pub fn to_lattice(&self, p: [f64; 2]) -> [f64; 2] {
        let q = self.orientation.apply_f64(p);
        [self.origin.0 as f64 + q[0], self.origin.1 as f64 + q[1]]
    }

    /// The placement of a child given in this tile's `scale`-refined frame,
    /// on the `scale`-refined lattice.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::{Orientation, Placement};
    /// let parent = Placement::new((1, 1), Orientation::IDENTITY);
    /// let child = parent.child(&Placement::new((1, 0), Orientation::IDENTITY), 2);
    /// assert_eq!(child.origin, (3, 2));
    /// ```
    pub fn child(&self, child: &Placement, scale: Lattice) -> Placement {
        let o = self.orientation.apply(child.origin);
        Placement {
            origin: (scale * self.origin.0 + o.0, scale * self.origin.1 + o.1),
            orientation: child.orientation.then(self.orientation),
        }
    }
}

/// Lower-left corner of the image of cell `c` under `origin + orientation`.
fn cell_image(
    origin: (Lattice, Lattice),
    orientation: Orientation,
    c: (Lattice, Lattice),
) -> (Lattice, Lattice) {
    let doubled = orientation.apply((2 * c.0 + 1, 2 * c.1 + 1));
    (
        origin.0 + (doubled.0 - 1) / 2,
        origin.1 + (doubled.1 - 1) / 2,
    )
}

/// A rep-tile production rule: the children of a tile, given as placements
/// in the parent's frame refined `scale` times, each with the rule its own
/// children use and its rank among siblings (the code digit).
///
/// # Example
/// ```
/// use tessera::polyomino::{Shape, Rule};
/// let rules = Rule::p_pentomino_rules();
/// assert_eq!(rules.len(), 2);
/// assert!(rules[0].tiles_parent(&Shape::p_pentomino()));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rule {
    /// Linear scale factor between parent and children.
    pub scale: Lattice,
    /// Child placements in the parent's refined frame.
    pub children: Vec<Placement>,
}

impl Rule {
    /// Whether the children cover the `scale`-times enlarged parent exactly,
    /// cell by cell.
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::{Shape, Rule};
    /// for rule in Rule::p_pentomino_rules() {
    ///     assert!(rule.tiles_parent(&Shape::p_pentomino()));
    /// }
    /// ```
    pub fn tiles_parent(&self, shape: &Shape) -> bool {
        let mut target: Vec<(Lattice, Lattice)> = shape.scaled(self.scale).cells().to_vec();
        let mut covered: Vec<(Lattice, Lattice)> = self
            .children
            .iter()
            .flat_map(|p| p.cells(shape).collect::<Vec<_>>())
            .collect();
        target.sort_unstable();
        covered.sort_unstable();
        target == covered
    }

    /// The dissections of `shape` enlarged `scale` times into `scale^2`
    /// copies of itself (at most `limit`), found by exact-cover search, each
    /// with its children in a canonical order (sorted by origin, orientation).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::{Rule, Shape};
    /// let rules = Rule::dissections(&Shape::p_pentomino(), 2, usize::MAX);
    /// assert_eq!(rules.len(), 2);
    /// ```
    pub fn dissections(shape: &Shape, scale: Lattice, limit: usize) -> Vec<Rule> {
        let region = shape.scaled(scale).cells().to_vec();
        let mut found = exact_cover::tilings(shape, &region, limit, 0);
        for children in &mut found {
            children.sort_by_key(|p| (p.origin, p.orientation));
        }
        found.sort_by_key(|c| {
            c.iter()
                .map(|p| (p.origin, p.orientation))
                .collect::<Vec<_>>()
        });
        found
            .into_iter()
            .map(|children| Rule { scale, children })
            .collect()
    }

    /// The two dissections of the doubled P-pentomino into four P-pentominoes
    /// (the search finds exactly two).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Rule;
    /// assert_ne!(Rule::p_pentomino_rules()[0], Rule::p_pentomino_rules()[1]);
    /// ```
    pub fn p_pentomino_rules() -> Vec<Rule> {
        Rule::dissections(&Shape::p_pentomino(), 2, usize::MAX)
    }
}

impl Shape {
    /// The outline as a closed loop of lattice vertices, counter-clockwise,
    /// one vertex per unit step (assumes a simply connected shape).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::new(vec![(0, 0)]).outline(), vec![(0, 0), (1, 0), (1, 1), (0, 1)]);
    /// assert_eq!(Shape::p_pentomino().outline().len(), 10);
    /// ```
    pub fn outline(&self) -> Vec<(Lattice, Lattice)> {
        use std::collections::HashMap;
        let has = |c: (Lattice, Lattice)| self.cells.contains(&c);
        // directed boundary edges with the shape on their left
        let mut next: HashMap<(Lattice, Lattice), (Lattice, Lattice)> = HashMap::new();
        for &(x, y) in &self.cells {
            if !has((x, y - 1)) {
                next.insert((x, y), (x + 1, y));
            }
            if !has((x + 1, y)) {
                next.insert((x + 1, y), (x + 1, y + 1));
            }
            if !has((x, y + 1)) {
                next.insert((x + 1, y + 1), (x, y + 1));
            }
            if !has((x - 1, y)) {
                next.insert((x, y + 1), (x, y));
            }
        }
        let Some(&start) = next.keys().min() else {
            return Vec::new();
        };
        let mut loop_ = vec![start];
        let mut at = next[&start];
        while at != start && loop_.len() <= next.len() {
            loop_.push(at);
            at = next[&at];
        }
        loop_
    }
}

impl Shape {
    /// The shape grown by one cell in every direction (8-neighbourhood).
    ///
    /// # Example
    /// ```
    /// use tessera::polyomino::Shape;
    /// assert_eq!(Shape::new(vec![(0, 0)]).dilated().cells().len(), 9);
    /// assert!(Shape::p_pentomino().dilated().contains([-0.5, 3.5]));
    /// ```
    pub fn dilated(&self) -> Shape {
        let mut cells: Vec<(Lattice, Lattice)> = self
            .cells
            .iter()
            .flat_map(|&(x, y)| {
                (-1..=1).flat_map(move |dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            })
            .collect();
        cells.sort_unstable();
        cells.dedup();
        Shape::new(cells)
    }
}
