//! The worlds benchmark end to end on its smoke size: one effect world and one null world,
//! recorded, closed blind, scored against the truth; the table has its rows. Whether the loop
//! finds the effect is the benchmark's measurement, not this test's; that the oracle sees an
//! effect drawn at ten times its realistic size is.

use drift_sim::world::effects::EffectFamily;
use experiments::worlds::{run_world, table, Kind};

#[test]
fn one_effect_world_and_one_null_world_are_scored_into_the_table() {
    let work = tempfile::tempdir().unwrap();
    let kinds = [Kind::Effect(EffectFamily::Humidity), Kind::Null];
    let scores: Vec<_> = kinds
        .iter()
        .map(|&kind| run_world(kind, 3, work.path(), true, 10.0).unwrap())
        .collect();
    for s in &scores {
        assert_eq!(s.axes.len(), 3);
        for a in &s.axes {
            assert!(a.drift.0.is_finite() && a.drift.1.is_finite() && a.drift.2.is_finite());
            assert!(!a.cut.ratio.is_nan(), "{s:?}");
            assert!(a.top != "–", "a ranking on every axis: {s:?}");
        }
        assert!(s.record_seconds > 0.0 && s.loop_seconds > 0.0);
    }
    // A humidity world moves every axis; a null world none.
    assert!(scores[0].axes.iter().all(|a| a.affected));
    // The oracle scores the true regressor on every axis of the effect world, and only there; at
    // ten times the realistic size the truth explains a clear share out of sample, detectably on
    // some axis (the scores of seed 3: 0.64, 0.29, 0.75).
    assert!(scores[1].axes.iter().all(|a| a.oracle.is_none()));
    for a in &scores[0].axes {
        let o = a.oracle.as_ref();
        let o = o.unwrap_or_else(|| panic!("no oracle on {}", a.axis));
        assert!(o.rank >= 1 && (0.0..=1.0).contains(&o.gain), "{o:?}");
        assert!(o.detectable_share > 0.0, "{o:?}");
    }
    let oracles: Vec<_> = scores[0].axes.iter().map(|a| &a.oracle).collect();
    let clear = oracles
        .iter()
        .filter(|o| o.as_ref().is_some_and(|o| o.gain > 0.2))
        .count();
    assert!(clear >= 2, "{oracles:?}");
    assert!(
        scores[0].axes.iter().any(|a| a.oracle_detectable()),
        "{oracles:?}"
    );
    // Given the truth as a channel, the loop admits it and cuts the held-out drift excess: at ten
    // times the realistic size, surely more than 1× on some axis (seed 3: 19× on X).
    assert!(
        oracles
            .iter()
            .filter_map(|o| o.as_ref())
            .any(|o| o.admitted && o.cut.low > 1.0),
        "{oracles:?}"
    );
    assert!(scores[1]
        .axes
        .iter()
        .all(|a| !a.affected && !a.right_family));
    // Nothing of a world is left on disk (the empty truth folder aside).
    let left: Vec<_> = walk(work.path());
    assert!(left.is_empty(), "left behind: {left:?}");
    let text = table(&scores, &[], &kinds);
    for row in [
        "| humidity | 1 | 3 |",
        "| null | 1 | 3 |",
        "| humidity | 1 | 0 |",
        "| null | 1 | 0 |",
    ] {
        assert!(text.contains(row), "no `{row}` in\n{text}");
    }
}

fn walk(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().filter_map(Result::ok) {
        let path = entry.path();
        if path.is_dir() {
            files.extend(walk(&path));
        } else {
            files.push(path);
        }
    }
    files
}
