//! The one error that is not a failure: `check` ran and found a limit missed (exit status 1).

/// `check` ran and a unit × axis missed a limit: exit status 1, unlike every other error (2).
#[derive(Debug)]
pub struct LimitsMissed(pub String);

impl std::fmt::Display for LimitsMissed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for LimitsMissed {}
