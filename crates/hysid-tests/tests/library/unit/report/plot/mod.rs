//! Tests of `hysid::report::plot`.

mod axis;
mod prepare;

mod render_tests {
    // Renders every kind of plot and checks the SVG text.

    use hysid::report::plot::{
        hline, render, render_panels, render_panels_sized, Figure, Series, Style,
    };

    /// Checks that `svg` is a complete document with the given texts and no non-finite number.
    /// Returns its size.
    fn check_svg(svg: &str, texts: &[&str]) -> usize {
        assert!(
            svg.starts_with("<svg") || svg.starts_with("<?xml"),
            "bad start"
        );
        assert!(svg.trim_end().ends_with("</svg>"), "bad end");
        for t in texts {
            assert!(svg.contains(t), "missing text {t:?}");
        }
        assert!(
            !svg.contains("NaN") && !svg.contains("inf"),
            "non-finite leaked"
        );
        svg.len()
    }

    fn time(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|i| i as f64 * dt).collect()
    }

    #[test]
    fn single_panel_time_plot() {
        let t = time(2_000, 0.01);
        let y: Vec<f64> = t.iter().map(|t| (t * 2.0).sin()).collect();
        let yh: Vec<f64> = t.iter().map(|t| 0.95 * (t * 2.0 + 0.05).sin()).collect();
        let fig = Figure::new("Output, fit 93.2 %", "time [s]", "force [N]")
            .with(Series::line("measured", &t, &y))
            .with(Series::dashed("simulated", &t, &yh));
        let svg = render(&fig).unwrap();
        check_svg(
            &svg,
            &[
                "Output, fit 93.2 %",
                "time [s]",
                "force [N]",
                "measured",
                "simulated",
            ],
        );
    }

    #[test]
    fn hysteresis_loops() {
        let mut figs_x = Vec::new();
        let mut figs_y = Vec::new();
        for amp in [0.5, 1.0, 1.5] {
            let x: Vec<f64> = (0..400).map(|i| amp * (i as f64 * 0.0157).sin()).collect();
            let y: Vec<f64> = (0..400)
                .map(|i| amp * (i as f64 * 0.0157 - 0.3).sin())
                .collect();
            figs_x.push(x);
            figs_y.push(y);
        }
        let labels = ["A = 0.5", "A = 1.0", "A = 1.5"];
        let mut fig = Figure::new("Hysteresis loops", "displacement [mm]", "force [N]");
        for i in 0..3 {
            fig.series
                .push(Series::line(labels[i], &figs_x[i], &figs_y[i]));
        }
        let svg = render(&fig).unwrap();
        check_svg(
            &svg,
            &[
                "Hysteresis loops",
                "displacement [mm]",
                "force [N]",
                "A = 1.5",
            ],
        );
    }

    #[test]
    fn six_panel_parameter_grid() {
        let it = time(50, 1.0);
        let names = [
            "k [N/m]",
            "c [N s/m]",
            "alpha [-]",
            "beta [1/m]",
            "gamma [1/m]",
            "n [-]",
        ];
        let truth = [2.0e4, 35.0, 0.3, 1.2e-3, -0.5, 1.0];
        let est: Vec<Vec<f64>> = truth
            .iter()
            .map(|&v| {
                it.iter()
                    .map(|k| v * (1.0 + 0.5 * (-k / 8.0f64).exp()))
                    .collect()
            })
            .collect();
        let panels: Vec<Figure> = (0..6)
            .map(|i| {
                Figure::new(names[i], "iteration", names[i])
                    .with(Series::new("estimate", &it[..], &est[i][..], Style::Line))
                    .with(hline("true value", (0.0, 49.0), truth[i]))
            })
            .collect();
        let svg = render_panels("Parameter convergence", &panels, 2).unwrap();
        let mut texts = vec!["Parameter convergence", "iteration", "true value"];
        texts.extend(names);
        check_svg(&svg, &texts);
    }

    #[test]
    fn million_points_are_decimated() {
        let n = 1_000_000;
        let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
        // Noise plus a slow sine: the worst case for a naive polyline.
        let y: Vec<f64> = (0..n)
            .map(|i| (i as f64 * 1e-4).sin() + ((i * 2_654_435_761usize) % 1000) as f64 * 1e-4)
            .collect();
        let fig = Figure::new("Input signal", "sample index [-]", "voltage [V]")
            .with(Series::line("u", &x, &y))
            .with(Series::dashed("u (dashed copy)", &x, &y));
        let svg = render(&fig).unwrap();
        let size = check_svg(&svg, &["Input signal", "sample index [-]", "voltage [V]"]);
        eprintln!("10^6-point plot (line + dashed): {size} bytes");
        assert!(size < 1_000_000, "SVG too large: {size} bytes");

        let fig = Figure::new("Scatter", "x [-]", "y [-]").with(Series::points("p", &x, &y));
        let svg = render(&fig).unwrap();
        let size = check_svg(&svg, &["Scatter"]);
        eprintln!("10^6-point scatter: {size} bytes");
        assert!(size < 1_000_000, "SVG too large: {size} bytes");
    }

    #[test]
    fn indexed_series() {
        let u: Vec<f64> = (0..3000).map(|i| ((i / 100) % 2) as f64).collect();
        let fig =
            Figure::new("Input", "sample [-]", "u [V]").with(Series::indexed("u", &u, Style::Line));
        let svg = render(&fig).unwrap();
        check_svg(&svg, &["Input", "sample [-]", "u [V]"]);
    }

    #[test]
    fn empty_series_and_figures() {
        let fig = Figure::new("Empty", "time [s]", "y [m]").with(Series::line("nothing", &[], &[]));
        let svg = render(&fig).unwrap();
        check_svg(&svg, &["Empty", "time [s]", "y [m]", "nothing", "no data"]);

        let bare = Figure::new("", "", "");
        let svg = render(&bare).unwrap();
        check_svg(&svg, &[]);

        let svg = render_panels("No panels", &[], 2).unwrap();
        check_svg(&svg, &["No panels"]);

        let svg = render_panels("Zero columns", &[fig.clone(), bare], 0).unwrap();
        check_svg(&svg, &["Zero columns", "Empty"]);
    }

    #[test]
    fn nan_and_infinite_values_are_skipped() {
        let t = time(100, 0.1);
        let mut y: Vec<f64> = t.iter().map(|t| t.cos()).collect();
        y[10] = f64::NAN;
        y[50] = f64::INFINITY;
        y[51] = f64::NEG_INFINITY;
        let all_nan = vec![f64::NAN; 100];
        let short = [1.0, 2.0];
        let fig = Figure::new("With gaps", "time [s]", "y [m]")
            .with(Series::line("gappy", &t, &y))
            .with(Series::dashed("all missing", &t, &all_nan))
            .with(Series::points("mismatched lengths", &t, &short));
        let svg = render(&fig).unwrap();
        check_svg(
            &svg,
            &["With gaps", "time [s]", "y [m]", "gappy", "all missing"],
        );
    }

    #[test]
    fn constant_and_extreme_series() {
        let t = time(100, 1.0);
        let c = vec![3.7; 100];
        let z = vec![0.0; 100];
        let fig = Figure::new("Constant", "time [s]", "y [m]")
            .with(Series::line("c", &t, &c))
            .with(Series::line("zero", &t, &z));
        let svg = render(&fig).unwrap();
        check_svg(&svg, &["Constant", "time [s]", "y [m]"]);

        let one = Figure::new("Single point", "x", "y").with(Series::points("p", &[1.0], &[2.0]));
        let svg = render(&one).unwrap();
        check_svg(&svg, &["Single point"]);

        let huge = [-f64::MAX, 0.0, f64::MAX];
        let tiny = [1e-300, 2e-300, 3e-300];
        let fig = Figure::new("Extremes", "x", "y")
            .with(Series::line("huge", &huge, &huge))
            .with(Series::line("tiny", &tiny, &tiny));
        let svg = render(&fig).unwrap();
        check_svg(&svg, &["Extremes"]);
        let fig = Figure::new("Tiny", "x", "y").with(Series::line("tiny", &tiny, &tiny));
        let svg = render(&fig).unwrap();
        check_svg(&svg, &["Tiny"]);
    }

    #[test]
    fn odd_sizes_and_paths() {
        let mut fig =
            Figure::new("Small", "x", "y").with(Series::line("a", &[0.0, 1.0], &[0.0, 1.0]));
        fig.size = (0, 0);
        let svg = render(&fig).unwrap();
        check_svg(&svg, &["Small"]);
        let svg = render_panels_sized("Grid", &[fig.clone()], 3, (1, 1)).unwrap();
        check_svg(&svg, &["Grid", "Small"]);
    }

    #[test]
    fn many_panels_in_a_tiny_canvas() {
        let x = [0.0, 1.0, 2.0];
        let panels: Vec<Figure> = (0..50)
            .map(|_| Figure::new("p", "x", "y").with(Series::line("a", &x, &x)))
            .collect();
        // Either a drawing or a clean error is fine; a panic is not.
        let r = render_panels_sized("Crowded", &panels, 1, (200, 150));
        eprintln!("crowded grid: {r:?}");
        let svg = render_panels("Many", &panels, 7).unwrap();
        check_svg(&svg, &["Many"]);
    }
}
