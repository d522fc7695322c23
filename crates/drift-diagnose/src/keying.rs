//! What the loop's model reads from the heating history on each axis — stage 3's lookup, the warm
//! starts' initial bias — and what the unit's firmware kept before each of its activations: the
//! model the diagnosis looks behind.
//!
//! The loop diagnoses the residual of the model it would ship. Where stage 3 keyed by heating
//! history ([`drift_fit::FittedUnit::by_history`]) leaves less drift on the training activations, or
//! the warm starts' initial bias leaves less error, that is the model, and a residual the paper's
//! model leaves but this one does not is no longer the diagnosis's to explain.

use std::collections::HashMap;

use drift_core::{ModifiedTables, Previous};
use drift_recording::Segment;

use drift_evaluate::evaluate::correct_segment_after;

/// Per axis, stage 3 keyed by history or by rise and the initial bias with or without warm starts,
/// and per activation what firmware kept of the one before. Activations are known by their
/// switch-on time: one unit's are distinct (the order `kept_before` lives them in), and a copy
/// carrying another quantity in its rates (an absorber's) keeps it.
#[derive(Debug, Clone, Default)]
pub struct Keying {
    /// Per axis: stage 3 keyed by heating history.
    pub by_history: [bool; 3],
    /// Per axis: the initial bias of warm starts (`drift_core::AmbientCurves::warm_starts`).
    pub warm_start: [bool; 3],
    kept: HashMap<u64, [Previous; 3]>,
}

impl Keying {
    /// `by_history` per axis, without warm starts, with `kept[i]` what firmware kept before
    /// `segments[i]`.
    pub fn new(by_history: [bool; 3], segments: &[&Segment], kept: &[[Previous; 3]]) -> Self {
        Self {
            by_history,
            warm_start: [false; 3],
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
            ..self.clone()
        }
    }

    /// The same with warm starts' initial bias on `warm_start`'s axes.
    pub fn with_warm_start(&self, warm_start: [bool; 3]) -> Self {
        Self {
            warm_start,
            ..self.clone()
        }
    }

    /// Whether any axis reads the heating history (stage 3 or the initial bias).
    pub fn any(&self) -> bool {
        self.by_history.iter().chain(&self.warm_start).any(|&k| k)
    }

    /// The tables of the loop's model: per axis `by_rise`'s, or `by_history`'s where keyed by
    /// history (both fitted to the same curves, so they share settings and extension), with
    /// `by_history`'s warm starts where chosen and none elsewhere. Boxed: tables are 160 KiB, and
    /// unoptimised builds keep several copies of a value on the stack.
    pub fn tables(
        &self,
        by_rise: &ModifiedTables,
        by_history: &ModifiedTables,
    ) -> Box<ModifiedTables> {
        let mut tables = Box::new(by_rise.clone());
        for (axis, table) in tables.axes.iter_mut().enumerate() {
            let history = &by_history.axes[axis];
            if self.by_history[axis] {
                *table = history.clone();
            }
            for (ambient, fitted) in table.ambients.iter_mut().zip(&history.ambients) {
                ambient.warm_starts = if self.warm_start[axis] {
                    fitted.warm_starts.clone()
                } else {
                    heapless::Vec::new()
                };
            }
        }
        tables
    }

    /// What firmware kept before `segment`, to start it with `power_on_after` as the loop's
    /// firmware does: an axis that reads the history finds its stage 3 or initial bias there, and
    /// the extension's rate filter its cooling at switch-on; tables that read neither start as
    /// after `power_on`. An activation this keying was not built with has nothing kept (a cold
    /// start, flagged where the tables read the history).
    pub fn previous(&self, segment: &Segment) -> Option<[Previous; 3]> {
        Some(self.kept(segment))
    }

    /// What firmware kept before `segment`, whether or not an axis reads it (nothing, for an
    /// activation this keying was not built with).
    pub fn kept(&self, segment: &Segment) -> [Previous; 3] {
        self.kept
            .get(&segment.power_on_ns)
            .copied()
            .unwrap_or(Previous::NOTHING)
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
