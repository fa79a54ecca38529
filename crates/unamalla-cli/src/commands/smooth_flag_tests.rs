//! Unit tests of the `smooth` flags: how the command-line options map onto the driver options.

use super::*;
use optim::drivers::{ClassicCombination, HomotopySchedule};
use optim::{KFunctional, PointwiseMode, SmoothFunctional, Solver};

fn flags(functional: &str, solver: &str) -> SmoothFlags {
    SmoothFlags {
        functional: functional.into(),
        solver: solver.into(),
        ..SmoothFlags::default()
    }
}

#[test]
fn every_flag_reaches_the_library_options() {
    let o = SmoothFlags {
        sigma: Some(0.9),
        homotopy: Some("sine".into()),
        presmooth: 3,
        ..flags("karea-length", "lbfgs")
    };
    let o = SmoothFlags {
        lbfgs_memory: Some(3),
        pointwise_mode: Some("components".into()),
        ..o
    }
    .options()
    .unwrap();
    assert_eq!(
        o.functional,
        SmoothFunctional::AdaptiveK {
            functional: KFunctional::KAreaLength,
            sigma: 0.9
        }
    );
    assert_eq!(o.schedule, HomotopySchedule::Sine);
    assert_eq!(o.presmooth, 3);
    assert_eq!(o.solver.solver, Solver::Lbfgs);
    assert_eq!(o.solver.lbfgs_memory, 3);
    assert_eq!(o.solver.pointwise_mode, PointwiseMode::Components);
    // defaults: the functional's own σ, linear homotopy, memory 5, simultaneous
    let d = flags("area-length", "tn-tr").options().unwrap();
    assert_eq!(
        d.functional,
        SmoothFunctional::Classic {
            combination: ClassicCombination::AreaLength,
            sigma: 0.5
        }
    );
    assert_eq!(d.schedule, HomotopySchedule::Linear);
    assert_eq!(d.solver.lbfgs_memory, 5);
    assert_eq!(d.solver.pointwise_mode, PointwiseMode::Simultaneous);
}

#[test]
fn bad_flags_are_errors() {
    let bad = |f: SmoothFlags| f.options().is_err();
    assert!(bad(SmoothFlags {
        sigma: Some(-0.1),
        ..flags("ao-homega", "tn-tr")
    }));
    assert!(bad(SmoothFlags {
        sigma: Some(0.7),
        ..flags("area-ortho", "tn-tr")
    }));
    assert!(bad(SmoothFlags {
        sigma: Some(0.5),
        ..flags("homega", "tn-tr")
    }));
    assert!(bad(SmoothFlags {
        lbfgs_memory: Some(0),
        ..flags("ao-homega", "lbfgs")
    }));
    assert!(bad(SmoothFlags {
        homotopy: Some("t4".into()),
        ..flags("karea-length", "tn-tr")
    }));
    assert!(bad(flags("nonsense", "tn-tr")));
}
