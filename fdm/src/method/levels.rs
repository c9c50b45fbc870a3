//! The time levels a method advances: positions and velocities of a level ([`Levels`]) and
//! the state of a step ([`StepState`]).

/// Positions and velocities of one time level.
pub struct Levels {
    pub q: Vec<f64>,
    pub v: Vec<f64>,
}

impl Levels {
    pub fn new(n: usize) -> Self {
        Levels {
            q: vec![0.0; n],
            v: vec![0.0; n],
        }
    }
}

/// The levels a method advances: y_{j−1}, y_j and the new y_{j+1}, the accelerations at j and
/// j+1, the predicted step-end velocity, and the model's powers at j and j+1 (for the ledger).
pub struct StepState {
    pub prev: Levels,
    pub cur: Levels,
    pub next: Levels,
    /// a(t_j, q_j, v_j)
    pub acc: Vec<f64>,
    /// a at the new level (after [`super::Stepper::complete`]); scratch before
    pub acc_next: Vec<f64>,
    /// the step-end velocity a one-step method predicts before its force evaluation
    pub pred: Vec<f64>,
    /// powers at level j and at the new level
    pub p_cur: Vec<f64>,
    pub p_new: Vec<f64>,
}

impl StepState {
    /// `n` coordinates, `np` powers, at rest.
    pub fn new(n: usize, np: usize) -> Self {
        StepState {
            prev: Levels::new(n),
            cur: Levels::new(n),
            next: Levels::new(n),
            acc: vec![0.0; n],
            acc_next: vec![0.0; n],
            pred: vec![0.0; n],
            p_cur: vec![0.0; np],
            p_new: vec![0.0; np],
        }
    }

    /// The new level becomes level j (and level j becomes j−1).
    pub fn rotate(&mut self) {
        std::mem::swap(&mut self.prev, &mut self.cur);
        std::mem::swap(&mut self.cur, &mut self.next);
        std::mem::swap(&mut self.acc, &mut self.acc_next);
        std::mem::swap(&mut self.p_cur, &mut self.p_new);
    }
}
