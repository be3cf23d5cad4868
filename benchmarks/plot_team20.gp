# Plot of benchmarks/team20 (docs/validation.md "TEAM 20"). Run from the repository root:
#   build/bin/team20 && gnuplot benchmarks/plot_team20.gp
# Writes benchmarks/results/team20.png. team20_cut_cells.csv: the earlier
# rule (cut cells of volume share w), for comparison.
set datafile separator ","
R = "benchmarks/results/"
csv = R."team20.csv"
old = R."team20_cut_cells.csv"
# team20.csv columns: 1 hx_mm, 2 hy_mm, 3 hz_mm, 4 cells, 5 pole_cells, 6 threads, 7 setup_s, 8 ampere_turns,
# 9 solve_s, 10 newton, 11 gmres, 12 matvecs, 13 residual, 14 force_N, 15 force_measured_N, 16 force_error,
# 17 Bz_P1_T, 18 Bz_P1_measured_T, 19 Bz_P1_error, 20 Bz_P2_T, 21 Bz_P2_measured_T, 22 Bz_P2_error,
# 23 momentum_balance (team20_cut_cells.csv: one h_mm column instead of the three and no matvecs, the
# others the same).
at(n, col) = (column(4) == n) ? column(col) : NaN
old_at(h, col) = (abs(column(1) - h) < 1e-3) ? column(col) : NaN
set terminal pngcairo size 1100,450 font "sans,10"
set output R."team20.png"
set multiplot layout 1,2 title "TEAM 20: steel pole in a yoke, FFT lattices + Newton-GMRES, against the measured values"
set grid
set key top left
set xlabel "ampere-turns"
set ylabel "force on the pole (N)"
set xrange [0:5500]
set yrange [0:100]
plot csv using 8:15 every ::1 w p pt 7 ps 1.5 lc rgb "black" t "measured", \
     csv using 8:(at(2375, 14)) w lp pt 6 lc rgb "#1f77b4" t "h = 5 mm (2375 cells)", \
     csv using 8:(at(9400, 14)) w lp pt 4 lc rgb "#2ca02c" t "2.5 x 2.5 x 5 mm (9400)", \
     csv using 8:(at(18800, 14)) w lp pt 8 lc rgb "#d62728" t "h = 2.5 mm (18800)", \
     old using 6:(old_at(2.5, 11)) w lp pt 1 dt 2 lc rgb "gray" t "cut cells, h = 2.5 mm"
set ylabel "relative force error (%)"
set xlabel "solve time per excitation (s)"
set logscale x
set autoscale x
set yrange [-20:7]
set key bottom right
# The rows cycle through the four excitations (every 4th row after the header: one excitation).
AT = "1000 3000 4500 5000"
plot for [i = 1:4] csv skip 1 every 4::(i - 1) using 9:(100 * column(16)) w lp pt 7 t word(AT, i)." AT", \
     5 w l lc rgb "red" dt 2 t "+-5%", -5 w l lc rgb "red" dt 2 notitle
unset multiplot
