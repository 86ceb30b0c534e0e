#!/usr/bin/env bash
# Plots the scaling curve of `cleave bench`: time per cell of every stage against the number of
# cells (log x), from the tab-separated table that `cleave bench --scaling FILE` writes.
#
# Usage: scripts/bench-plot.sh [TABLE] [PNG]
#   TABLE  default docs/performance-scaling.tsv
#   PNG    default docs/performance-scaling.png
# Produce the table first, e.g.:
#   build/release/bin/cleave bench --models scaling --peers none --repeat 5 --scaling docs/performance-scaling.tsv
# Needs gnuplot (Debian package gnuplot-nox, listed in scripts/install-deps.sh).
set -euo pipefail

table=${1:-docs/performance-scaling.tsv}
png=${2:-docs/performance-scaling.png}
[ -f "$table" ] || { echo "bench-plot: no table at $table (run cleave bench --scaling $table first)" >&2; exit 2; }
command -v gnuplot >/dev/null || { echo "bench-plot: gnuplot not found; run scripts/install-deps.sh" >&2; exit 2; }

gnuplot <<GNUPLOT
set terminal pngcairo size 1100,700 enhanced font "DejaVu Sans,12"
set output "$png"
set datafile separator "\t"
set datafile missing "-"
set title "cleave bench: time per cell of each stage (median), tube at increasing resolution"
set xlabel "cells"
set ylabel "time per cell (µs)"
set logscale x
set logscale y
set format x "10^{%L}"
set grid xtics ytics mxtics mytics lc rgb "#dddddd"
set key below box opaque maxrows 3
set xrange [3000:2000000]
# Columns (cleave bench --scaling): 1 model, 2 cells, 3 vertices, then us per cell of 4 vector,
# 5 value (stroke edit; 0 with the default w_E = 0, so not plotted), 6 value_point, 7 equilibrate,
# 8 preview, 9 step, 10 update; "-" where a stage was skipped (design stages above
# --design-max-cells).
plot "$table" using 2:4 with linespoints lw 2 pt 7 title "eigenvector interpolation (stroke edit)", \
     "" using 2:6 with linespoints lw 2 pt 5 title "eigenvalue interpolation (control-point edit)", \
     "" using 2:7 with linespoints lw 2 pt 9 title "equilibration", \
     "" using 2:8 with linespoints lw 3 pt 11 title "incision preview solve", \
     "" using 2:9 with linespoints lw 3 pt 13 title "dynamic step (during a cut)", \
     "" using 2:10 with linespoints lw 2 pt 3 dt 2 title "edit-to-picture update"
GNUPLOT
echo "bench-plot: wrote $png"
