# Speed against error of TEAM 20's quarter model (docs/validation.md "TEAM 20",
# "Under 1 s"). Run from the repository root after the two team20 runs of
# docs/benchmarks.md (team20_quarter_uniform and team20_quarter_fast):
#   gnuplot benchmarks/plot_team20_quarter.gp
# Writes benchmarks/results/team20_quarter.png.
set datafile separator ","
R = "benchmarks/results/"
# Columns of both CSVs: 1 h_min_mm, 2 growth, 3 h_max_mm, 4 cells, 5 pole_cells, 6 unknown_cells,
# 7 threads, 8 setup_s, 9 ampere_turns, 10 solve_s, 11 newton, 12 gmres, 13 matvecs, 14 residual,
# 15 force_N, 16 force_measured_N, 17 force_error, ...
set terminal pngcairo size 1100,450 font "sans,10"
set output R."team20_quarter.png"
set multiplot layout 1,2 title "TEAM 20, quarter model (uniform cells): force error against solve time per excitation"
set grid
set logscale x
set xrange [0.003:50]
set yrange [-32:10]
set xlabel "solve time per excitation (s)"
set ylabel "force error against the measured value (%)"
set key bottom right
AT = "1000 3000 4500 5000"
do for [f in "team20_quarter_uniform team20_quarter_fast"] {
  set title (f eq "team20_quarter_uniform" ? "compressed operator, 1 thread, tolerance 1e-4" : \
             "single precision, 2 threads, tolerance 1e-3")
  set arrow 1 from first 1, graph 0 to first 1, graph 1 nohead lc rgb "black" dt 3 lw 1.5
  plot for [i = 1:4] R.f.".csv" skip 1 every 4::(i - 1) using 10:(100 * column(17)) w lp pt 7 t word(AT, i)." AT", \
       5 w l lc rgb "red" dt 2 t "+-5%", -5 w l lc rgb "red" dt 2 notitle
}
unset multiplot
