# Plots of speed_vs_error (docs/validation.md). Run from the repository root:
#   build-bench/bin/speed_vs_error > benchmarks/results/speed_vs_error.csv
#   gnuplot benchmarks/plot_speed_error.gp
# Writes benchmarks/results/speed_sphere.png, speed_cuboid.png, speed_crane.png.
set datafile separator ","
R = "benchmarks/results/"
csv = R."speed_vs_error.csv"
# Columns: 1 study, 2 case, 3 param_name, 4 param, 5 h_mm, 6 cells,
# 7 iterations, 8 converged, 9 seconds, 10 error_max, 11 error_rms.
sel(st, c, col) = (strcol(1) eq st && strcol(2) eq c) ? column(col) : NaN
lattice(st, c, col) = (strcol(1) eq st && strcol(2) eq c && column(4) > 0) ? column(col) : NaN
set logscale xy
set format y "10^{%T}"
set format x "10^{%T}"
set grid
set key font ",9"

# ---- soft sphere -------------------------------------------------------------
set terminal pngcairo size 1100,500 font "sans,10"
set output R."speed_sphere.png"
set multiplot layout 1,2 title "Soft lattice sphere in a uniform field (one cell: exact, error 1e-14, not shown)"
set xlabel "cells (h = R/1 .. R/8)"
set ylabel "relative error"
set yrange [0.01:1]
set key top right
plot for [c in "chi=10 chi=1000 chi=inf"] csv using (lattice("sphere", c, 6)):(lattice("sphere", c, 10)) w lp pt 7 t c." moment", \
     for [c in "chi=10 chi=1000 chi=inf"] csv using (lattice("sphere", c, 6)):(lattice("sphere", c, 11)) w lp pt 6 dt 2 t c." field at 1.5 R", \
     0.05 w l lc rgb "red" dt 2 t "5%"
set xlabel "relaxation time (s), tolerance 1e-8"
set autoscale x
plot for [c in "chi=10 chi=1000 chi=inf"] csv using (lattice("sphere", c, 9)):(lattice("sphere", c, 10)) w lp pt 7 t c." moment", \
     0.05 w l lc rgb "red" dt 2 t "5%"
unset multiplot

# ---- permanent cuboid ------------------------------------------------------------
set output R."speed_cuboid.png"
set multiplot layout 1,2 title "Permanent 20x10x5 mm box vs the closed form, planes at a gap g below a face (e = 5 mm)"
set xlabel "cell size h (mm)"
set ylabel "relative RMS error of H on the plane"
set autoscale
set yrange [1e-16:1]
set key right center
plot for [g in "0.1e 0.5e 1e 2e"] csv using (sel("cuboid", "dipole gap=".g, 5)):(sel("cuboid", "dipole gap=".g, 11)) w lp pt 7 t "dipole sum, g = ".g, \
     for [g in "0.1e 2e"] csv using (sel("cuboid", "probe gap=".g, 5)):(sel("cuboid", "probe gap=".g, 11)) w lp pt 6 dt 2 t "probe (exact cubes), g = ".g
set xlabel "time for 169 points (s)"
plot for [g in "0.1e 0.5e 1e 2e"] csv using (sel("cuboid", "dipole gap=".g, 9)):(sel("cuboid", "dipole gap=".g, 11)) w lp pt 7 t "dipole sum, g = ".g, \
     for [g in "0.1e 2e"] csv using (sel("cuboid", "probe gap=".g, 9)):(sel("cuboid", "probe gap=".g, 11)) w lp pt 6 dt 2 t "probe, g = ".g
unset multiplot

# ---- crane ---------------------------------------------------------------------
set output R."speed_crane.png"
set terminal pngcairo size 1100,500 font "sans,10"
set multiplot layout 1,2 title "Crane: magnet + 197 touching steel balls; force error vs tolerance-1e-10 reference"
set autoscale
set yrange [1e-11:1]
set xlabel "max\\_iterations"
set ylabel "max_b |F_b - F_{ref,b}| / max_b |F_{ref,b}|"
set key bottom left
plot for [t in "1e-02 1e-03 1e-04 1e-05 1e-06 1e-07 1e-08"] csv using (sel("crane", "cold tol=".t, 4)):(sel("crane", "cold tol=".t, 10)) w lp pt 7 t "cold, tol ".t, \
     for [t in "1e-02 1e-04 1e-06 1e-08"] csv using (sel("crane", "warm tol=".t, 4)):(sel("crane", "warm tol=".t, 10)) w lp pt 6 dt 2 t "warm, tol ".t
set xlabel "relaxation + forces (s)"
plot for [t in "1e-02 1e-03 1e-04 1e-05 1e-06 1e-07 1e-08"] csv using (sel("crane", "cold tol=".t, 9)):(sel("crane", "cold tol=".t, 10)) w p pt 7 t "cold, tol ".t, \
     for [t in "1e-02 1e-04 1e-06 1e-08"] csv using (sel("crane", "warm tol=".t, 9)):(sel("crane", "warm tol=".t, 10)) w p pt 6 t "warm, tol ".t
unset multiplot
