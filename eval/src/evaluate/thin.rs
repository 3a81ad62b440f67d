//! Series thinned for drawing, one point at a time in bounded memory: up to `2·BUCKETS` points
//! are kept as they are; past that, the points fall into time buckets (at most `2·BUCKETS`,
//! their width doubling as the series grows) and each bucket keeps its lowest and highest
//! point, in time order, so spikes survive. Angle series are broken into pieces where they jump
//! by more than 180° (a wrap at ±180°), each piece thinned on its own.

/// Buckets of a long series: about this many, at most twice as many.
pub const BUCKETS: usize = 2000;

/// Pieces of a thinned series, each a list of `(t, value)`.
pub type Pieces = Vec<Vec<(f64, f64)>>;

#[derive(Clone, Copy, Debug)]
struct Bucket {
    piece: usize,
    index: u64,
    lo: (f64, f64),
    hi: (f64, f64),
}

/// A series being thinned (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Thinner {
    wraps: bool,
    piece: usize,
    last: Option<f64>,
    raw: Vec<(usize, (f64, f64))>,
    /// `(first t, bucket width)` once bucketed.
    grid: Option<(f64, f64)>,
    buckets: Vec<Bucket>,
}

impl Thinner {
    /// A series of angles in degrees, broken where it wraps.
    pub fn angles() -> Self {
        Self {
            wraps: true,
            ..Self::default()
        }
    }

    /// Adds a point; `t` must not decrease.
    pub fn push(&mut self, t: f64, v: f64) {
        if self.wraps && self.last.is_some_and(|l| (v - l).abs() > 180.0) {
            self.piece += 1;
        }
        self.last = Some(v);
        match self.grid {
            None => {
                self.raw.push((self.piece, (t, v)));
                if self.raw.len() > 2 * BUCKETS {
                    let first = self.raw[0].1 .0;
                    let width = ((t - first) / BUCKETS as f64).max(f64::MIN_POSITIVE);
                    self.grid = Some((first, width));
                    for (piece, p) in std::mem::take(&mut self.raw) {
                        self.bucket(piece, p);
                    }
                }
            }
            Some(_) => self.bucket(self.piece, (t, v)),
        }
    }

    fn bucket(&mut self, piece: usize, p: (f64, f64)) {
        let Some((first, width)) = self.grid else {
            return;
        };
        let index = ((p.0 - first) / width) as u64;
        match self.buckets.last_mut() {
            Some(b) if b.piece == piece && b.index == index => {
                if p.1 < b.lo.1 {
                    b.lo = p;
                }
                if p.1 > b.hi.1 {
                    b.hi = p;
                }
            }
            _ => self.buckets.push(Bucket {
                piece,
                index,
                lo: p,
                hi: p,
            }),
        }
        if self.buckets.len() > 2 * BUCKETS {
            self.grid = Some((first, 2.0 * width));
            let mut merged: Vec<Bucket> = Vec::with_capacity(BUCKETS + 1);
            for mut b in std::mem::take(&mut self.buckets) {
                b.index /= 2;
                match merged.last_mut() {
                    Some(m) if m.piece == b.piece && m.index == b.index => {
                        if b.lo.1 < m.lo.1 {
                            m.lo = b.lo;
                        }
                        if b.hi.1 > m.hi.1 {
                            m.hi = b.hi;
                        }
                    }
                    _ => merged.push(b),
                }
            }
            self.buckets = merged;
        }
    }

    /// The pieces, thinned.
    pub fn pieces(&self) -> Pieces {
        let mut pieces: Pieces = Vec::new();
        let mut current = None;
        let mut add = |piece: usize, points: &[(f64, f64)]| {
            if current != Some(piece) {
                pieces.push(Vec::new());
                current = Some(piece);
            }
            if let Some(p) = pieces.last_mut() {
                p.extend_from_slice(points);
            }
        };
        for &(piece, p) in &self.raw {
            add(piece, &[p]);
        }
        for b in &self.buckets {
            let pair = if b.lo.0 <= b.hi.0 {
                [b.lo, b.hi]
            } else {
                [b.hi, b.lo]
            };
            add(b.piece, if b.lo == b.hi { &pair[..1] } else { &pair });
        }
        pieces
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_series_stay_whole_and_break_at_wraps() {
        let mut t = Thinner::angles();
        for (i, v) in [170.0, 179.0, -179.0, -170.0].iter().enumerate() {
            t.push(i as f64, *v);
        }
        assert_eq!(
            t.pieces(),
            vec![
                vec![(0.0, 170.0), (1.0, 179.0)],
                vec![(2.0, -179.0), (3.0, -170.0)]
            ]
        );
    }

    #[test]
    fn long_series_keep_their_extremes_in_bounded_buckets() {
        let mut t = Thinner::default();
        let n = 1_000_000;
        for k in 0..n {
            let v = if k == 777_777 { 50.0 } else { (k % 10) as f64 };
            t.push(k as f64, v);
        }
        let pieces = t.pieces();
        assert_eq!(pieces.len(), 1);
        let points = &pieces[0];
        assert!(points.len() <= 4 * BUCKETS + 2, "{}", points.len());
        assert!(points.len() >= BUCKETS, "{}", points.len());
        assert!(points.contains(&(777_777.0, 50.0)), "the spike survives");
        assert!(points.windows(2).all(|w| w[0].0 <= w[1].0), "in time order");
    }
}
