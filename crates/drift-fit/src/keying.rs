//! Which lookup stage 3 uses on each axis of the loop's model, and what the unit's firmware kept
//! before each of its activations: the model the diagnosis looks behind.
//!
//! The loop diagnoses the residual of the model it would ship. Where stage 3 keyed by heating
//! history ([`crate::FittedUnit::by_history`]) leaves less drift on the training activations, that is the
//! model, and a residual the paper's lookup by rise leaves but the history-keyed one does not is
//! no longer the diagnosis's to explain.

use std::collections::HashMap;

use drift_core::{ModifiedTables, Previous};
use drift_recording::Segment;

use crate::evaluate::correct_segment_after;

/// Per axis, stage 3 keyed by history or by rise, and per activation what firmware kept of the one
/// before. Activations are known by their switch-on time: one unit's are distinct (the order
/// `kept_before` lives them in), and a copy carrying another quantity in its rates (an absorber's)
/// keeps it.
#[derive(Debug, Clone, Default)]
pub struct Keying {
    /// Per axis: stage 3 keyed by heating history.
    pub by_history: [bool; 3],
    kept: HashMap<u64, [Previous; 3]>,
}

impl Keying {
    /// `by_history` per axis, with `kept[i]` what firmware kept before `segments[i]`.
    pub fn new(by_history: [bool; 3], segments: &[&Segment], kept: &[[Previous; 3]]) -> Self {
        Self {
            by_history,
            kept: segments
                .iter()
                .zip(kept)
                .map(|(s, k)| (s.power_on_ns, *k))
                .collect(),
        }
    }

    /// The same activations and kept history with stage 3 keyed by history on `by_history`'s
    /// axes.
    pub fn with_by_history(&self, by_history: [bool; 3]) -> Self {
        Self {
            by_history,
            kept: self.kept.clone(),
        }
    }

    /// Whether any axis is keyed by history.
    pub fn any(&self) -> bool {
        self.by_history.iter().any(|&k| k)
    }

    /// The tables of the loop's model: `by_rise`'s axes, with `by_history`'s on the axes keyed by
    /// history (both fitted to the same curves, so they share settings and extension). Boxed:
    /// tables are 160 KiB, and unoptimised builds keep several copies of a value on the stack.
    pub fn tables(
        &self,
        by_rise: &ModifiedTables,
        by_history: &ModifiedTables,
    ) -> Box<ModifiedTables> {
        let mut tables = Box::new(by_rise.clone());
        for (axis, keyed) in self.by_history.iter().enumerate() {
            if *keyed {
                tables.axes[axis] = by_history.axes[axis].clone();
            }
        }
        tables
    }

    /// What firmware kept before `segment`, when an axis is keyed by history (`None`: the
    /// paper's `power_on`). An activation this keying was not built with has nothing kept (a
    /// cold start, flagged).
    pub fn previous(&self, segment: &Segment) -> Option<[Previous; 3]> {
        self.any().then(|| {
            self.kept
                .get(&segment.power_on_ns)
                .copied()
                .unwrap_or(Previous::NOTHING)
        })
    }

    /// Corrects `segment` with `tables` (from [`Self::tables`]), started after what firmware kept
    /// before it when an axis is keyed by history.
    pub fn correct(
        &self,
        tables: &ModifiedTables,
        segment: &Segment,
        switch_on: [f32; 3],
    ) -> ([Vec<f32>; 3], [u16; 3]) {
        correct_segment_after(tables, segment, switch_on, self.previous(segment).as_ref())
    }
}
