# The crane's time line (docs/benchmarks.md section 4). Run from the
# repository root after benchmarks/crane_timeline.sh; reads
# benchmarks/results/crane_timeline.csv (rows labelled "before" and "after")
# and writes benchmarks/results/crane_timeline.png.
set datafile separator ","
if (!exists("R")) R = "benchmarks/results/"
csv = R."crane_timeline.csv"
# Columns: 1 label, 2 time_s, 4 T_m mean, 5 T_m max, 6 T_r mean, 7 T_r max,
# 8 iterations mean, 9 substeps mean, 10 dense evaluation (ms).
rows(l) = sprintf("< awk -F, '$1 == \"%s\"' %s", l, csv)
set terminal pngcairo size 1400,900 font "sans,10"
set output R."crane_timeline.png"
set multiplot layout 2,2 title "Crane (paper Fig. 17, 490 balls, 690 cells, 1 ms steps): means over 10 ms; phases: descent | grip | lift | hold | reduced | off"
set grid
set key top left
set xlabel "simulated time (s)"
set xrange [0:5]
do for [t in "0.8 1.3 2.3 3.0 4.0"] { set arrow from t+0, graph 0 to t+0, graph 1 nohead dt 3 lc rgb "gray50" }
set logscale y
set ylabel "ms per rigid step"
set title "T_m (magnetic)"
plot rows("before") using 2:4 w l lw 1.5 lc rgb "#c0392b" t "before", rows("after") using 2:4 w l lw 1.5 lc rgb "#2471a3" t "after", \
     rows("after") using 2:10 w l lw 1 dt 2 lc rgb "#2471a3" t "after: one dense field evaluation"
set title "T_r (rigid: collision and quick step)"
plot rows("before") using 2:6 w l lw 1.5 lc rgb "#c0392b" t "before", rows("after") using 2:6 w l lw 1.5 lc rgb "#2471a3" t "after"
unset logscale y
set ylabel "outer iterations per rigid step"
set title "outer relaxation iterations (summed over substeps)"
plot rows("before") using 2:8 w l lw 1.5 lc rgb "#c0392b" t "before", rows("after") using 2:8 w l lw 1.5 lc rgb "#2471a3" t "after"
set ylabel "substeps per rigid step"
set title "substeps"
plot rows("before") using 2:9 w l lw 1.5 lc rgb "#c0392b" t "before", rows("after") using 2:9 w l lw 1.5 lc rgb "#2471a3" t "after"
unset multiplot
