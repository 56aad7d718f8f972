//! Pixel geometry: rectangles, data-to-pixel mapping, clipping, decimation
//! and an occupancy grid for legend placement.

use crate::scale::AxisRange;

/// A rectangle of pixels; all four edges are inclusive (the frame of a
/// plotting area is drawn on its edge pixels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PixelRect {
    /// Leftmost pixel column.
    pub left: i32,
    /// Topmost pixel row.
    pub top: i32,
    /// Rightmost pixel column.
    pub right: i32,
    /// Bottom pixel row.
    pub bottom: i32,
}

impl PixelRect {
    /// Whether pixel (x, y) lies in the rectangle (edges included).
    pub fn contains(&self, x: i32, y: i32) -> bool {
        x >= self.left && x <= self.right && y >= self.top && y <= self.bottom
    }

    /// Number of pixel columns.
    pub fn width(&self) -> i32 {
        self.right - self.left + 1
    }

    /// Number of pixel rows.
    pub fn height(&self) -> i32 {
        self.bottom - self.top + 1
    }

    /// Whether the two rectangles share at least one pixel.
    pub fn intersects(&self, other: &PixelRect) -> bool {
        self.left <= other.right
            && other.left <= self.right
            && self.top <= other.bottom
            && other.top <= self.bottom
    }
}

/// A point in pixel space (x to the right, y downwards).
pub(crate) type Pt = (f64, f64);

/// Maps data coordinates into a plotting rectangle.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mapper {
    pub rect: PixelRect,
    pub x: AxisRange,
    pub y: AxisRange,
}

impl Mapper {
    pub fn px(&self, x: f64) -> f64 {
        let r = self.rect;
        f64::from(r.left) + (x - self.x.min) / self.x.span() * f64::from(r.right - r.left)
    }

    pub fn py(&self, y: f64) -> f64 {
        let r = self.rect;
        f64::from(r.bottom) - (y - self.y.min) / self.y.span() * f64::from(r.bottom - r.top)
    }
}

/// Axis-aligned clip box in pixel space.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ClipBox {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl ClipBox {
    /// The rectangle shrunk by `inset` pixels on every side.
    pub fn inside(rect: PixelRect, inset: f64) -> Self {
        let cx = 0.5 * f64::from(rect.left + rect.right);
        let cy = 0.5 * f64::from(rect.top + rect.bottom);
        ClipBox {
            x0: (f64::from(rect.left) + inset).min(cx),
            y0: (f64::from(rect.top) + inset).min(cy),
            x1: (f64::from(rect.right) - inset).max(cx),
            y1: (f64::from(rect.bottom) - inset).max(cy),
        }
    }

    pub fn contains(&self, p: Pt) -> bool {
        p.0 >= self.x0 && p.0 <= self.x1 && p.1 >= self.y0 && p.1 <= self.y1
    }

    /// Liang–Barsky: the part of segment a–b inside the box, if any.
    pub fn clip_segment(&self, a: Pt, b: Pt) -> Option<(Pt, Pt)> {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let mut t0 = 0.0f64;
        let mut t1 = 1.0f64;
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
                if t0 > t1 {
                    return None;
                }
            }
        }
        Some((
            (a.0 + t0 * dx, a.1 + t0 * dy),
            (a.0 + t1 * dx, a.1 + t1 * dy),
        ))
    }

    /// The parts of a polyline inside the box (single points kept if inside).
    pub fn clip_polyline(&self, pts: &[Pt]) -> Vec<Vec<Pt>> {
        let mut out: Vec<Vec<Pt>> = Vec::new();
        if pts.len() == 1 {
            if self.contains(pts[0]) {
                out.push(vec![pts[0]]);
            }
            return out;
        }
        let mut cur: Vec<Pt> = Vec::new();
        for w in pts.windows(2) {
            match self.clip_segment(w[0], w[1]) {
                Some((a, b)) => {
                    let continues = cur.last().is_some_and(|l| l.0 == a.0 && l.1 == a.1);
                    if !continues {
                        if cur.len() > 1 {
                            out.push(std::mem::take(&mut cur));
                        }
                        cur.clear();
                        cur.push(a);
                    }
                    cur.push(b);
                }
                None => {
                    if cur.len() > 1 {
                        out.push(std::mem::take(&mut cur));
                    }
                    cur.clear();
                }
            }
        }
        if cur.len() > 1 {
            out.push(cur);
        }
        out
    }
}

/// Min/max decimation per pixel column ("M4"): of each run of consecutive
/// points in the same pixel column keeps the first, the lowest, the highest
/// and the last, in their original order. Works for non-monotonic x too
/// (loops), and never loses an extreme.
pub(crate) fn decimate(pts: &[Pt]) -> Vec<Pt> {
    if pts.len() <= 4 {
        return pts.to_vec();
    }
    let mut out = Vec::with_capacity(pts.len().min(4096));
    let mut start = 0usize;
    while start < pts.len() {
        let col = pts[start].0.floor();
        let mut end = start + 1;
        let (mut lo, mut hi) = (start, start);
        while end < pts.len() && pts[end].0.floor() == col {
            if pts[end].1 < pts[lo].1 {
                lo = end;
            }
            if pts[end].1 > pts[hi].1 {
                hi = end;
            }
            end += 1;
        }
        let last = end - 1;
        let mut keep = [start, lo, hi, last];
        keep.sort_unstable();
        let mut prev = usize::MAX;
        for k in keep {
            if k != prev {
                out.push(pts[k]);
                prev = k;
            }
        }
        start = end;
    }
    out
}

/// Coarse grid marking where something has been drawn, to find a free
/// corner for a legend.
pub(crate) struct Occupancy {
    rect: PixelRect,
    cell: i32,
    cols: usize,
    rows: usize,
    cells: Vec<bool>,
}

impl Occupancy {
    pub fn new(rect: PixelRect, cell: i32) -> Self {
        let cell = cell.max(1);
        let cols = (rect.width().max(1) / cell + 1) as usize;
        let rows = (rect.height().max(1) / cell + 1) as usize;
        Occupancy {
            rect,
            cell,
            cols,
            rows,
            cells: vec![false; cols * rows],
        }
    }

    pub fn mark_point(&mut self, p: Pt) {
        if !(p.0.is_finite() && p.1.is_finite()) {
            return;
        }
        let c = ((p.0 - f64::from(self.rect.left)) / f64::from(self.cell)).floor();
        let r = ((p.1 - f64::from(self.rect.top)) / f64::from(self.cell)).floor();
        if c >= 0.0 && r >= 0.0 && (c as usize) < self.cols && (r as usize) < self.rows {
            self.cells[r as usize * self.cols + c as usize] = true;
        }
    }

    pub fn mark_polyline(&mut self, pts: &[Pt]) {
        if let Some(&p) = pts.first() {
            self.mark_point(p);
        }
        let step = f64::from(self.cell) * 0.5;
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
            let n = ((len / step).ceil() as usize).min(100_000);
            for k in 1..=n {
                let t = k as f64 / n as f64;
                self.mark_point((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
            }
        }
    }

    /// Marks a horizontal band (e.g. a bar) of the grid.
    pub fn mark_rect(&mut self, r: PixelRect) {
        let mut y = r.top;
        while y <= r.bottom {
            let mut x = r.left;
            while x <= r.right {
                self.mark_point((f64::from(x), f64::from(y)));
                x += self.cell;
            }
            self.mark_point((f64::from(r.right), f64::from(y)));
            y += self.cell;
        }
        let mut x = r.left;
        while x <= r.right {
            self.mark_point((f64::from(x), f64::from(r.bottom)));
            x += self.cell;
        }
    }

    /// Fraction of the cells touching the rectangle that are marked.
    pub fn fraction(&self, r: PixelRect) -> f64 {
        let cols = (r.right.min(self.rect.right) - r.left.max(self.rect.left)) / self.cell + 1;
        let rows = (r.bottom.min(self.rect.bottom) - r.top.max(self.rect.top)) / self.cell + 1;
        if cols <= 0 || rows <= 0 {
            return 0.0;
        }
        self.count(r) as f64 / f64::from(cols * rows)
    }

    /// Number of marked cells touching the rectangle.
    pub fn count(&self, r: PixelRect) -> usize {
        let c0 = ((r.left - self.rect.left) / self.cell).max(0) as usize;
        let r0 = ((r.top - self.rect.top) / self.cell).max(0) as usize;
        let c1 = (((r.right - self.rect.left) / self.cell).max(0) as usize).min(self.cols - 1);
        let r1 = (((r.bottom - self.rect.top) / self.cell).max(0) as usize).min(self.rows - 1);
        let mut n = 0;
        for row in r0..=r1 {
            for col in c0..=c1 {
                if self.cells[row * self.cols + col] {
                    n += 1;
                }
            }
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_extremes() {
        let pts: Vec<Pt> = (0..100_000)
            .map(|i| {
                let x = i as f64 / 100.0; // 100 points per pixel column
                let y = if i == 54_321 {
                    -500.0
                } else {
                    (i as f64 * 0.37).sin() * 10.0
                };
                (x, y)
            })
            .collect();
        let d = decimate(&pts);
        assert!(d.len() <= 4 * 1000);
        assert!(d.iter().any(|p| p.1 == -500.0));
        let max = pts.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        assert!(d.iter().any(|p| p.1 == max));
        assert_eq!(d.first(), pts.first());
        assert_eq!(d.last(), pts.last());
    }

    #[test]
    fn clipping() {
        let b = ClipBox {
            x0: 0.0,
            y0: 0.0,
            x1: 10.0,
            y1: 10.0,
        };
        let parts = b.clip_polyline(&[
            (-5.0, 5.0),
            (5.0, 5.0),
            (15.0, 5.0),
            (15.0, 8.0),
            (5.0, 8.0),
        ]);
        assert_eq!(parts.len(), 2);
        for p in parts.iter().flatten() {
            assert!(b.contains(*p));
        }
        assert!(b.clip_polyline(&[(20.0, 20.0)]).is_empty());
        assert!(b.clip_segment((20.0, 0.0), (20.0, 10.0)).is_none());
    }

    #[test]
    fn occupancy_counts() {
        let rect = PixelRect {
            left: 0,
            top: 0,
            right: 99,
            bottom: 99,
        };
        let mut o = Occupancy::new(rect, 5);
        o.mark_polyline(&[(0.0, 0.0), (99.0, 99.0)]);
        let corner = PixelRect {
            left: 70,
            top: 0,
            right: 99,
            bottom: 20,
        };
        assert_eq!(o.count(corner), 0);
        assert_eq!(o.fraction(corner), 0.0);
        assert!(o.count(rect) > 10);
        assert!(o.fraction(rect) > 0.0 && o.fraction(rect) < 0.2);
    }
}
