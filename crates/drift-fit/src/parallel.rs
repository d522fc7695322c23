//! The three axes are fitted independently: one rayon task each.

/// `[f(0), f(1), f(2)]`, the axes on rayon's threads (nested inside a parallel loop over units or
/// activations, rayon shares the cores among them all).
pub fn per_axis<T: Send>(f: impl Fn(usize) -> T + Sync) -> [T; 3] {
    let (x, (y, z)) = rayon::join(|| f(0), || rayon::join(|| f(1), || f(2)));
    [x, y, z]
}
