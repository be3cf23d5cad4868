# Plot of cpu_scaling (docs/benchmarks.md "Scaling"). Run from the repository root:
#   build-bench/bin/cpu_scaling && gnuplot benchmarks/plot_scaling.gp
# Writes benchmarks/results/cpu_scaling.png.
set datafile separator ","
R = "benchmarks/results/"
csv = R."cpu_scaling.csv"
# Columns: 1 layout, 3 responsive_cells, 5 threads, 11 ms_per_iteration,
# 15 field_ms, 18 ns_per_pair, 20 gflops, 21 peak_gflops, 25
# force_ns_per_pair, 29 core_ns_per_pair, 30 gflops_per_core (CPU time).
rows(l, t) = sprintf("< awk -F, '$1 == \"%s\" && $5 == %d' %s", l, t, csv)
peak1 = system("awk -F, '$5 == 1 { print $21; exit }' ".csv) + 0
peak2 = system("awk -F, '$5 == 2 { print $21; exit }' ".csv) + 0
name(l, t) = sprintf("%s, %d thread%s", l, t, t > 1 ? "s" : "")

set terminal pngcairo size 1650,520 font "sans,10"
set output R."cpu_scaling.png"
set multiplot layout 1,3 title "CPU backend: soft block next to a magnet (lattice: one iron body, table sums; balls: one-cell bodies, dense kernel)"
set logscale xy
set grid
set key top left font ",8"
set xlabel "responsive cells"
set xrange [48:22000]
set format x "%g"

set ylabel "ms"
set title "per outer iteration (lines), per field evaluation (points)"
plot for [l in "lattice balls"] for [t=1:2] rows(l, t) using 3:11 w l lw 2 dt t t name(l, t)." / iteration", \
     for [l in "lattice balls"] for [t=1:2] rows(l, t) using 3:15 w p pt (t == 1 ? 6 : 7) t name(l, t)." / field"

set ylabel "ns per pair"
set title "field evaluation per pair: wall (solid), core-ns from CPU time (dashed)"
plot for [l in "lattice balls"] for [t=1:2] rows(l, t) using 3:18 w lp pt 7 lw 2 t name(l, t), \
     for [l in "lattice balls"] rows(l, 1) using 3:29 w lp pt 6 dt 2 t l.", core-ns (CPU time)", \
     rows("balls", 1) using 3:25 w lp pt 4 dt 3 t "balls, 1 thread, force and field"

set ylabel "GFLOP/s"
set title sprintf("achieved GFLOP/s (counted flops); peak %.0f (1 core), %.0f (2 cores)", peak1, peak2)
set yrange [1:300]
plot for [l in "lattice balls"] for [t=1:2] rows(l, t) using 3:20 w lp pt 7 lw 2 t name(l, t), \
     for [l in "lattice balls"] rows(l, 1) using 3:30 w lp pt 6 dt 2 t l.", per core (CPU time)", \
     rows("balls", 1) using 3:26 w lp pt 4 dt 3 t "balls, 1 thread, force", \
     peak1 w l lc rgb "red" dt 2 t "peak, 1 core", peak2 w l lc rgb "red" t "peak, 2 cores"
unset multiplot
