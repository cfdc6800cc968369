# The README's picture: the default scenario, its truth and four configurations' dead reckoning.
# Made from real runs (about a minute on two cores), in an empty directory:
#   wheelins simulate --out default -q
#   for c in single dual-wheel body-wheel triple; do
#     wheelins run -m default/manifest.yaml -c $c -o $c --formats csv,tum -q; done
#   wheelins evaluate --truth default/GINS.bin --traj triple/trajectory.tum --export-truth truth.tum
#   gnuplot -e 'outfile="trajectory.png"' path/to/docs/images/trajectory.gp
# truth.tum (NED, the manifest's origin): x north, y east; from the CSVs north_m and east_m.
if (!exists("outfile")) outfile = "trajectory.png"
set terminal pngcairo size 900,620 noenhanced font "Sans,11" linewidth 1.2
set output outfile
set datafile separator whitespace
set title "Default scenario (simulated, field profile): truth and dead reckoning, 4 configurations"
set size ratio -1
set xlabel "East [m]"
set ylabel "North [m]"
set grid lc rgb "#e0e0e0"
set key outside right top vertical Left reverse box samplen 3 spacing 1.2
# None hides another: the first drawn is the widest, each later one narrower, dashed and
# slightly transparent.
plot "truth.tum" every 200 using 3:2 with lines lw 7 lc rgb "#c8c8c8" title "Truth", \
     "< tail -n +2 single/trajectory.csv | awk -F, 'NR % 20 == 1 {print $2, $3}'" using 2:1 with lines lw 4.2 dt 1 lc rgb "#30ff7f0e" title "single Wheel-INS", \
     "< tail -n +2 body-wheel/trajectory.csv | awk -F, 'NR % 20 == 1 {print $2, $3}'" using 2:1 with lines lw 3.3 dt (12,5) lc rgb "#302ca02c" title "Body/Wheel-INS", \
     "< tail -n +2 dual-wheel/trajectory.csv | awk -F, 'NR % 20 == 1 {print $2, $3}'" using 2:1 with lines lw 2.4 dt (4,4) lc rgb "#301f77b4" title "Dual Wheel-INS", \
     "< tail -n +2 triple/trajectory.csv | awk -F, 'NR % 20 == 1 {print $2, $3}'" using 2:1 with lines lw 1.6 dt (14,4,3,4) lc rgb "#30d62728" title "Triple INS", \
     "truth.tum" every ::0::0 using 3:2 with points pt 7 ps 1.8 lc rgb "#000000" title "Start"
