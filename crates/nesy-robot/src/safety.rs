//! The checks nesy makes before a call is sent to a robot.

use std::str::FromStr;

/// An axis-aligned box the tool must stay in (world frame, metres). A motion whose target
/// lies outside it is refused before it is sent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Workspace {
    /// Lower corner `[x, y, z]`.
    pub min: [f64; 3],
    /// Upper corner `[x, y, z]`.
    pub max: [f64; 3],
}

impl Workspace {
    /// The simulator's own workspace: the table's reachable area
    /// (`nesy_sim::world::FLOOR_AABB`) from 5 cm below the table top to 80 cm above it, the
    /// box the simulated robot itself refuses targets outside of.
    pub fn simulated() -> Workspace {
        let floor = nesy_sim::world::FLOOR_AABB;
        let top = nesy_sim::scene::TABLE_TOP;
        Workspace {
            min: [floor.min[0], floor.min[1], top - 0.05],
            max: [floor.max[0], floor.max[1], top + 0.8],
        }
    }

    /// True if `point` lies inside (boundary included).
    pub fn contains(&self, point: [f64; 3]) -> bool {
        (0..3).all(|i| point[i].is_finite() && point[i] >= self.min[i] && point[i] <= self.max[i])
    }
}

impl std::fmt::Display for Workspace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [x0, y0, z0] = self.min;
        let [x1, y1, z1] = self.max;
        write!(f, "x {x0:.3}..{x1:.3}, y {y0:.3}..{y1:.3}, z {z0:.3}..{z1:.3}")
    }
}

/// A workspace that could not be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("workspace {given:?}: {expected}")]
pub struct WorkspaceError {
    /// What was given.
    pub given: String,
    /// What was expected.
    pub expected: &'static str,
}

impl FromStr for Workspace {
    type Err = WorkspaceError;

    /// Reads `XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX` (metres).
    fn from_str(given: &str) -> Result<Workspace, WorkspaceError> {
        let error = |expected| WorkspaceError {
            given: given.to_owned(),
            expected,
        };
        let values: Vec<f64> = given
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| error("expected six numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX in metres"))?;
        let [x0, y0, z0, x1, y1, z1] = values[..] else {
            return Err(error(
                "expected six numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX in metres",
            ));
        };
        if values.iter().any(|v| !v.is_finite()) || x0 >= x1 || y0 >= y1 || z0 >= z1 {
            return Err(error(
                "expected finite numbers with each minimum below its maximum",
            ));
        }
        Ok(Workspace {
            min: [x0, y0, z0],
            max: [x1, y1, z1],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workspaces_read_and_check() {
        let w: Workspace = "0.1,-0.5,0.45,0.8,0.5,1.3".parse().unwrap();
        assert!(w.contains([0.4, 0.0, 0.6]));
        assert!(!w.contains([0.9, 0.0, 0.6]));
        assert!(!w.contains([0.4, 0.0, f64::NAN]));
        assert!("0.1,0.2".parse::<Workspace>().is_err());
        assert!(
            "0.8,-0.5,0.45,0.1,0.5,1.3"
                .parse::<Workspace>()
                .unwrap_err()
                .to_string()
                .contains("minimum")
        );
        let sim = Workspace::simulated();
        assert!(sim.contains([0.4, 0.0, 0.62]));
    }
}
