//! Tests of `hysid::identify::actuator`.

mod loops;

mod model_loop_tests {
    use hysid::identify::actuator::*;

    #[test]
    fn the_model_loop_closes_at_its_turning_points() {
        let (k1, k2, alpha, a, q) = (30.0, 5.0e3, 40.0, 900.0, 0.05);
        let fit = LoopFit {
            values: [k1, k2, alpha, a],
            std: [0.0; 4],
            rms: 0.0,
            loops: Vec::new(),
        };
        let (x, tau) = fit.model_loop(q, 200);
        assert_eq!(x.len(), 402);
        // Cu(±Q) = ±(A/α)·tanh(αQ): the branches meet at the turning points.
        let top = k1 * q + k2 * q.powi(3) + (a / alpha) * (alpha * q).tanh();
        assert!(
            (tau[200] - top).abs() < 1e-9 * top.abs(),
            "{} {top}",
            tau[200]
        );
        assert!((tau[201] - top).abs() < 1e-9 * top.abs());
        assert!((tau[0] + top).abs() < 1e-9 * top.abs());
    }
}
