//! The few statistics every crate of subfric reads records with, in one place: the median
//! (the mean of the middle two of an even count) and the upper median (a value of the data
//! itself: the middle one, or the upper of the middle two). NaN sorts last, by `total_cmp`.

/// The median of `v` (sorted in place): the middle value, the mean of the middle two for an
/// even count; `None` when empty.
///
/// ```
/// use subfric_data::stats::median;
/// assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
/// assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
/// assert_eq!(median(&mut []), None);
/// ```
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    Some(if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    })
}

/// The upper median of `v` (sorted in place): the middle value, the upper of the middle two
/// for an even count — always one of the values, where a reading of the record itself is
/// wanted rather than a point between two; `None` when empty.
///
/// ```
/// use subfric_data::stats::upper_median;
/// assert_eq!(upper_median(&mut [4.0, 1.0, 3.0, 2.0]), Some(3.0));
/// assert_eq!(upper_median(&mut [3.0, 1.0, 2.0]), Some(2.0));
/// ```
pub fn upper_median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// The `q` quantile of `sorted` (ascending), linear between order statistics (the 0.25 of
/// four values lies three quarters of the way from the first to the second); `q` is clamped to
/// 0..=1; NaN when empty.
///
/// ```
/// use subfric_data::stats::quantile;
/// assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.5), 2.5);
/// assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.25), 1.75);
/// assert_eq!(quantile(&[7.0], 0.9), 7.0);
/// assert!(quantile(&[], 0.5).is_nan());
/// ```
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let i = pos.floor() as usize;
    let f = pos - i as f64;
    match sorted.get(i + 1) {
        Some(next) => sorted[i] + f * (next - sorted[i]),
        None => sorted[i],
    }
}
