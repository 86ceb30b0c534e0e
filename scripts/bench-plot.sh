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
set terminal pngcairo size 1100,650 enhanced font "DejaVu Sans,12"
set output "$png"
set datafile separator "\t"
set datafile missing "-"
set title "cleave bench: time per cell of each stage, tube at increasing resolution"
set xlabel "cells"
set ylabel "time per cell (µs)"
set logscale x
set logscale y
set format x "10^{%L}"
set grid xtics ytics mxtics mytics lc rgb "#dddddd"
set key outside right top box opaque
set xrange [3000:2000000]
plot "$table" using 2:4 with linespoints lw 2 pt 7 title "eigenvector interpolation", \
     "" using 2:5 with linespoints lw 2 pt 5 title "eigenvalue interpolation", \
     "" using 2:6 with linespoints lw 2 pt 9 title "equilibration", \
     "" using 2:7 with linespoints lw 2 pt 11 title "incision preview solve", \
     "" using 2:8 with linespoints lw 2 pt 13 title "dynamic step", \
     "" using 2:9 with linespoints lw 2 pt 3 dt 2 title "edit-to-picture update"
GNUPLOT
echo "bench-plot: wrote $png"
