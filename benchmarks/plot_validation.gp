# Plots of the FEM validation (docs/validation.md). Run from the repository root:
#   build-bench/bin/fem_validation --profiles benchmarks/results > benchmarks/results/fem_validation.csv
#   gnuplot benchmarks/plot_validation.gp
# Reads benchmarks/results/fem_validation.csv and fem_{cuboids,softmag}_profile.csv,
# writes benchmarks/results/fem_error_vs_h.png, fem_error_vs_time.png,
# fem_cuboids_lines.png, fem_softmag_lines.png.
set datafile separator ","
set terminal pngcairo size 900,600 font "sans,11"
R = "benchmarks/results/"
csv = R."fem_validation.csv"

# fem_validation.csv columns: 1 dataset, 2 variant, 3 k, 4 h_mm, 5 cells,
# 6 iterations, 7 converged, 8 residual, 9 relax_s, 10 probe_s,
# 11-13 err per line, 14 err_total, 15 max_M_soft.
# Profile columns: 1 line, 2 distance, 3-5 FEM, then Bx, By, Bz per variant
# in the program's order (softmag: linear, llg, llg_iron, chi0, magnet_alone).
sel(ds, v, col) = (strcol(1) eq ds && strcol(2) eq v) ? column(col) : NaN
pos(x) = x > 0 ? x : NaN

set output R."fem_error_vs_h.png"
set title "FEM validation: relative RMS error of B along the sensor lines"
set logscale xy
set xlabel "cell size h (mm)"
set ylabel "relative RMS error"
set format y "10^{%T}"
set grid
set key inside bottom right font ",9"
set xrange [0.05:1.2]
set yrange [1e-3:0.4]
plot csv using (sel("fem-cuboids","recoil",4)):(sel("fem-cuboids","recoil",14)) w lp pt 7 lc 1 t "cuboids, recoil", \
     csv using (sel("fem-cuboids","recoil_point_dipole",4)):(sel("fem-cuboids","recoil_point_dipole",14)) w lp pt 6 dt 2 lc 1 t "cuboids, recoil, point-dipole intra", \
     csv using (sel("fem-cuboids","chi0",4)):(sel("fem-cuboids","chi0",14)) w lp pt 4 dt 3 lc 1 t "cuboids, chi = 0", \
     csv using (sel("fem-softmag","soft_linear",4)):(sel("fem-softmag","soft_linear",14)) w lp pt 5 lc 2 t "softmag, linear cube", \
     csv using (sel("fem-softmag","soft_llg",4)):(sel("fem-softmag","soft_llg",14)) w lp pt 2 dt 2 lc 2 t "softmag, LLG cube", \
     csv using (sel("fem-softmag","soft_llg_iron",4)):(sel("fem-softmag","soft_llg_iron",14)) w lp pt 9 dt 3 lc 3 t "softmag, LLG cube, iron Ms 1.6e6", \
     csv using (sel("fem-softmag","chi0",4)):(sel("fem-softmag","chi0",14)) w lp pt 4 dt 3 lc 2 t "softmag, magnet chi = 0", \
     csv using (sel("fem-softmag","magnet_alone",4)):(sel("fem-softmag","magnet_alone",14)) w lp pt 8 dt 4 lc 2 t "softmag, magnet alone", \
     0.05 w l lc rgb "red" dt 2 t "5% target"

set output R."fem_error_vs_time.png"
set title "FEM validation: error against relaxation time (2 threads)"
set xlabel "relaxation time (s), best of up to 5"
set format x "10^{%T}"
set xrange [*:*]
set autoscale x
plot csv using (pos(sel("fem-cuboids","recoil",9))):(sel("fem-cuboids","recoil",14)) w lp pt 7 lc 1 t "cuboids, recoil", \
     csv using (pos(sel("fem-cuboids","recoil_point_dipole",9))):(sel("fem-cuboids","recoil_point_dipole",14)) w lp pt 6 dt 2 lc 1 t "cuboids, point-dipole intra", \
     csv using (pos(sel("fem-softmag","soft_linear",9))):(sel("fem-softmag","soft_linear",14)) w lp pt 5 lc 2 t "softmag, linear cube", \
     csv using (pos(sel("fem-softmag","soft_llg",9))):(sel("fem-softmag","soft_llg",14)) w lp pt 2 dt 2 lc 2 t "softmag, LLG cube", \
     0.05 w l lc rgb "red" dt 2 t "5% target"

# Field profiles: FEM (points) and odemag at the finest h (lines).
unset logscale
set format y "%g"
set format x "%g"
set autoscale
set grid
set key inside top right
unset title
set output R."fem_cuboids_lines.png"
set terminal pngcairo size 900,1000 font "sans,11"
set multiplot layout 3,1 title "fem-cuboids: B along (-4, 0, -1) mm .. (4, 0, -1) mm"
p = R."fem_cuboids_profile.csv"
set xlabel "distance along the line (mm)"
do for [c=1:3] {
  name = c == 1 ? "Bx" : (c == 2 ? "By" : "Bz")
  set ylabel name." (mT)"
  plot p using 2:(1e3*column(2+c)) every 3 w p pt 6 ps 0.6 lc rgb "black" t "FEM", \
       p using 2:(1e3*column(5+c)) w l lw 2 lc 1 t "odemag, recoil", \
       p using 2:(1e3*column(8+c)) w l dt 2 lc 2 t "odemag, chi = 0"
}
unset multiplot

set output R."fem_softmag_lines.png"
set terminal pngcairo size 1000,1000 font "sans,10"
q = R."fem_softmag_profile.csv"
set multiplot layout 3,2 title "fem-softmag: B along x at y = 0 (odemag: finest h of each variant)"
do for [l=0:2] {
  do for [c=0:1] {
    name = c == 0 ? "Bx" : "Bz"
    col = c == 0 ? 0 : 2
    set title sprintf("%s at z = %d mm", name, -1 - 2*l)
    set ylabel name." (mT)"
    plot q index l using 2:(1e3*column(3+col)) every 2 w p pt 6 ps 0.5 lc rgb "black" t "FEM", \
         q index l using 2:(1e3*column(6+col)) w l lw 2 lc 1 t "linear cube", \
         q index l using 2:(1e3*column(12+col)) w l dt 3 lw 1.5 lc rgb "dark-green" t "LLG cube, iron Ms", \
         q index l using 2:(1e3*column(15+col)) w l dt 2 lc 2 t "magnet chi = 0", \
         q index l using 2:(1e3*column(18+col)) w l dt 4 lw 1.5 lc rgb "dark-orange" t "magnet alone (no cube)"
  }
}
unset multiplot
