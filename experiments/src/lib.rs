//! Research programs behind gyrodrift's measured tables, kept out of the product: they simulate
//! campaigns with hidden effects, run the product's fitting, evaluation and closed loop on them, and
//! (after the fact, never inside the fit) compare with the simulator's truth. See the README.

pub mod closed_loop;
pub mod judged;
pub mod memory;
pub mod oracle;
pub mod world_loop;
pub mod worlds;
