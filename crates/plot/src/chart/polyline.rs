//! Polylines in pixels: decimation of long records, and clipping to a plotting box.

use super::AxisRange;

/// A point in pixels.
pub(crate) type Pt = (f64, f64);

/// Min/max decimation per pixel column ("M4"): of each run of consecutive points in the same
/// pixel column keeps the first, the lowest, the highest and the last, in their original order.
/// Works for x that goes back and forth (loops) and never loses an extreme, so the line drawn
/// covers the same pixels as the full record.
pub(crate) fn decimate<T: Copy>(pts: &[T], pixel: impl Fn(&T) -> Pt) -> Vec<T> {
    if pts.len() <= 4 {
        return pts.to_vec();
    }
    let mut out = Vec::with_capacity(pts.len().min(8192));
    let mut start = 0usize;
    while start < pts.len() {
        let col = pixel(&pts[start]).0.floor();
        let mut end = start + 1;
        let (mut lo, mut hi) = (start, start);
        let (mut ylo, mut yhi) = (pixel(&pts[start]).1, pixel(&pts[start]).1);
        while end < pts.len() {
            let (x, y) = pixel(&pts[end]);
            if x.floor() != col {
                break;
            }
            if y < ylo {
                (lo, ylo) = (end, y);
            }
            if y > yhi {
                (hi, yhi) = (end, y);
            }
            end += 1;
        }
        let mut keep = [start, lo, hi, end - 1];
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

/// `pts` without the points that land on the same whole pixel as the point before them
/// (plotters draws at whole pixels, so the line drawn is the same; the SVG gets shorter).
pub(crate) fn distinct_pixels<T: Copy>(mut pts: Vec<T>, pixel: impl Fn(&T) -> Pt) -> Vec<T> {
    pts.dedup_by(|b, a| pixel(a) == pixel(b));
    pts
}

/// The part of segment a–b inside the box (Liang–Barsky), if any.
pub(crate) fn clip_segment(a: Pt, b: Pt, x: AxisRange, y: AxisRange) -> Option<(Pt, Pt)> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - x.min),
        (dx, x.max - a.0),
        (-dy, a.1 - y.min),
        (dy, y.max - a.1),
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

/// The runs of a polyline inside the box.
pub(crate) fn clip_polyline(pts: &[Pt], x: AxisRange, y: AxisRange) -> Vec<Vec<Pt>> {
    let inside = |p: &Pt| x.contains(p.0) && y.contains(p.1);
    if pts.iter().all(inside) {
        return vec![pts.to_vec()];
    }
    let mut out: Vec<Vec<Pt>> = Vec::new();
    let mut cur: Vec<Pt> = Vec::new();
    for w in pts.windows(2) {
        match clip_segment(w[0], w[1], x, y) {
            Some((a, b)) => {
                if cur.last() != Some(&a) {
                    if cur.len() > 1 {
                        out.push(std::mem::take(&mut cur));
                    }
                    cur = vec![a];
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
