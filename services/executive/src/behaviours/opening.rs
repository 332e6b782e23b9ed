//! An opening in a followed wall told by the side sonar (001 §3.2): "a large sonar reading
//! increase in the direction of the wall" starts it (past the wall by `jump_m`), "a marked drop
//! in the sonar reading" (the wall redetected: within half that of where the wall was; the robot
//! held its heading by dead reckoning meanwhile, so the wall may come back a little nearer or
//! further) ends it; each needs `confirm` readings in a row, so that a lost echo or a
//! neighbour's stray neither opens nor closes a door, and an opening is measured from the first
//! reading of each run.

use super::wall::Wall;

/// What a side reading told.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event {
    /// Nothing new (the wall goes on, or a run is not yet confirmed).
    None,
    /// An opening begins where the robot was at its first far reading.
    Opened { at: [f64; 2] },
    /// The wall is back: the opening ran from `from` to `to` (the robot's positions).
    Closed { from: [f64; 2], to: [f64; 2] },
}

/// The detector's state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Opening {
    jump_m: f64,
    confirm: u32,
    /// Inside an opening since there.
    open_from: Option<[f64; 2]>,
    /// The run of readings that would change that, and where it began.
    run: u32,
    run_from: [f64; 2],
}

impl Opening {
    pub fn new(jump_m: f64, confirm: u32) -> Self {
        Self { jump_m, confirm: confirm.max(1), open_from: None, run: 0, run_from: [0.0; 2] }
    }

    /// Whether the robot is beside an opening.
    pub fn is_open(&self) -> bool {
        self.open_from.is_some()
    }

    /// One side reading at `at`: `distance_m` from the robot's centre, or none (no echo: a room
    /// deeper than the ring's range, or its far wall met at a glance, counts as far; `confirm`
    /// outvotes a lost echo). A reading on the wall is added to the wall's fit while the wall is
    /// followed.
    pub fn reading(
        &mut self,
        wall: &mut Wall,
        at: [f64; 2],
        travelled_m: f64,
        distance_m: Option<f64>,
    ) -> Event {
        let d = distance_m.unwrap_or(f64::INFINITY);
        let on_wall = wall.fits(at, d);
        let far = d > wall.line.distance(at) + self.jump_m;
        match self.open_from {
            None if on_wall => {
                wall.add(at, travelled_m, d);
                self.run = 0;
            }
            None if far => {
                if self.run == 0 {
                    self.run_from = at;
                }
                self.run += 1;
                if self.run >= self.confirm {
                    (self.open_from, self.run) = (Some(self.run_from), 0);
                    return Event::Opened { at: self.run_from };
                }
            }
            // A short stray: the wall is neither there nor gone.
            None => self.run = 0,
            Some(from) if d < wall.line.distance(at) + self.jump_m / 2.0 => {
                if self.run == 0 {
                    self.run_from = at;
                }
                self.run += 1;
                if self.run >= self.confirm {
                    (self.open_from, self.run) = (None, 0);
                    wall.restart();
                    return Event::Closed { from, to: self.run_from };
                }
            }
            Some(_) => {
                if far {
                    self.run = 0;
                }
            }
        }
        Event::None
    }
}

#[cfg(test)]
mod tests {
    use super::super::wall::Line;
    use super::*;

    #[test]
    fn an_opening_needs_its_readings_in_a_row_and_is_measured_from_the_first() {
        // The wall y = 1, the robot along y = 0.5; a doorway from x = 2.0 to 2.9.
        let line = Line::seen_from([0.0, 0.0], std::f64::consts::FRAC_PI_2, 1.0);
        let mut wall = Wall::new(line, 1.0, (0.05, 0.05));
        let mut o = Opening::new(0.5, 2);
        let mut events = Vec::new();
        for k in 0..100 {
            let x = 0.04 * f64::from(k);
            let door = (2.0..2.9).contains(&x);
            let d = match k {
                // A lost echo in the doorway, a stray far reading before it, a short one in it,
                // a lost echo on the wall.
                60 | 30 => None,
                20 => Some(4.0),
                57 => Some(0.1),
                _ if door => Some(5.0),
                _ => Some(0.5),
            };
            match o.reading(&mut wall, [x, 0.5], x, d) {
                Event::None => {}
                e => events.push(e),
            }
        }
        assert_eq!(events.len(), 2, "{events:?}");
        let Event::Opened { at } = events[0] else { panic!("{events:?}") };
        assert!((at[0] - 2.0).abs() < 0.041, "{at:?}");
        let Event::Closed { from, to } = events[1] else { panic!("{events:?}") };
        assert_eq!(from, at);
        assert!((to[0] - 2.92).abs() < 0.041, "{to:?}");
        assert!(!o.is_open());
    }
}
