# Plot of benchmarks/team20 (docs/validation.md "TEAM 20"). Run from the repository root:
#   build/bin/team20 && gnuplot benchmarks/plot_team20.gp
# Writes benchmarks/results/team20.png.
set datafile separator ","
R = "benchmarks/results/"
csv = R."team20.csv"
# Columns: 1 h_mm, 2 cells, 3 pole_cells, 4 threads, 5 setup_s, 6 ampere_turns, 7 solve_s, 8 newton,
# 9 gmres, 10 residual, 11 force_N, 12 force_measured_N, 13 force_error, 14 Bz_P1_T, 15 Bz_P1_measured_T,
# 16 Bz_P1_error, 17 Bz_P2_T, 18 Bz_P2_measured_T, 19 Bz_P2_error, 20 momentum_balance
at_h(h, col) = (abs(column(1) - h) < 1e-3) ? column(col) : NaN
set terminal pngcairo size 1100,450 font "sans,10"
set output R."team20.png"
set multiplot layout 1,2 title "TEAM 20: steel pole in a yoke, FFT lattices + Newton-GMRES, against the measured values"
set grid
set key top left
set xlabel "ampere-turns"
set ylabel "force on the pole (N)"
set xrange [0:5500]
set yrange [0:100]
plot csv using 6:12 every ::1 w p pt 7 ps 1.5 lc rgb "black" t "measured", \
     for [h in "5 2.5"] csv using 6:(at_h(h + 0, 11)) w lp pt 6 t "h = ".h." mm"
set ylabel "relative force error (%)"
set xlabel "solve time per excitation (s)"
set logscale x
set autoscale xy
set key bottom right
plot for [a in "1000 3000 4500 5000"] csv using (column(6) == a ? column(7) : NaN):(100 * column(13)) w lp pt 7 t a." AT", \
     5 w l lc rgb "red" dt 2 t "+-5%", -5 w l lc rgb "red" dt 2 notitle
unset multiplot
