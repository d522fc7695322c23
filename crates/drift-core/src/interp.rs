//! Piecewise-linear interpolation: the one formula behind all three stages of the paper.
//!
//! The paper's printed formulas (`dt_k = d_(j-1) + (d_j - d_(j-1)) / (t_j - tx)`) are garbled; read as
//! in `READING.md` they are ordinary linear interpolation between the two bracketing knots:
//! `value(x) = v_lo + (v_hi - v_lo) · (x - x_lo) / (x_hi - x_lo)`.

/// Linear interpolation from `lo` (at `fraction = 0`) to `hi` (at `fraction = 1`).
///
/// Exact at `fraction = 0`, so a table value is reproduced bit for bit at its knot.
#[inline(always)]
pub(crate) fn lerp(lo: f32, hi: f32, fraction: f32) -> f32 {
    lo + (hi - lo) * fraction
}

/// Where `x` falls among strictly increasing knots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Bracket {
    /// Before the first knot.
    Below,
    /// Between knots `lo` and `lo + 1`, at `fraction` ∈ [0, 1) of the way; or exactly on the last
    /// knot with `fraction = 0` and `lo` = last.
    Inside { lo: usize, fraction: f32 },
    /// After the last knot.
    Above,
}

/// Locates `x` among `count` strictly increasing knots given by `knot(i)`.
///
/// Binary search (via `partition_point`, which cannot panic), then one division for the fraction.
/// `knot` is queried only with indices below `count`; a missing knot reads as NaN, which the caller's
/// finiteness check turns into a flag rather than a wrong number.
#[inline]
pub(crate) fn bracket<T>(knots: &[T], x: f32, position: impl Fn(&T) -> f32) -> Bracket {
    let above = knots.partition_point(|k| position(k) <= x);
    let Some(lo) = above.checked_sub(1) else {
        return Bracket::Below;
    };
    let x_lo = knots.get(lo).map_or(f32::NAN, &position);
    match knots.get(above) {
        Some(next) => {
            let x_hi = position(next);
            Bracket::Inside {
                lo,
                fraction: (x - x_lo) / (x_hi - x_lo),
            }
        }
        None if x > x_lo => Bracket::Above,
        None => Bracket::Inside { lo, fraction: 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brackets_inside_below_above_and_on_last_knot() {
        let knots = [1.0_f32, 2.0, 4.0];
        let id = |k: &f32| *k;
        assert_eq!(bracket(&knots, 0.5, id), Bracket::Below);
        assert_eq!(
            bracket(&knots, 1.0, id),
            Bracket::Inside {
                lo: 0,
                fraction: 0.0
            }
        );
        assert_eq!(
            bracket(&knots, 3.0, id),
            Bracket::Inside {
                lo: 1,
                fraction: 0.5
            }
        );
        assert_eq!(
            bracket(&knots, 4.0, id),
            Bracket::Inside {
                lo: 2,
                fraction: 0.0
            }
        );
        assert_eq!(bracket(&knots, 4.5, id), Bracket::Above);
        assert_eq!(bracket(&knots, f32::NAN, id), Bracket::Below);
        assert_eq!(bracket::<f32>(&[], 1.0, id), Bracket::Below);
    }

    #[test]
    fn lerp_is_exact_at_the_lower_knot() {
        assert_eq!(lerp(0.1, 0.7, 0.0), 0.1);
    }
}
