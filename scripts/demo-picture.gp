# scripts/demo-picture.sh's chart: two panels, each the points of one pcd_collision -o file
# (fields x y z intensity rgb label, binary) in a slice through the fingers, seen along y, in
# the colours the tool writes (free green, contact yellow, collision red, not evaluated grey).
# Input: dir (the runs' files), out (the PNG).
set terminal pngcairo size 1100,420 noenhanced font "DejaVu Sans,10"
set output out
set multiplot layout 1,2 title "The README demo's pose 2: gripper fingers 2 cm into the table top (data/table_mug.pcd), side view, slice 0.03 < y < 0.07 m"
set xrange [-0.25:-0.05]
set yrange [-0.03:0.072]
set size ratio -1
set xlabel "x (m)"
set ylabel "z (m)"
set grid lc rgb "#dddddd"
set key off
set label 1 "table top: scan points (b)" at -0.15, -0.012 center font ",9"
set label 2 "gripper: mesh samples (a)" at -0.15, 0.066 center font ",9"
set label 3 "green P < 0.1 (free), yellow 0.1-0.9 (contact), red P > 0.9 (collision), grey not evaluated" at screen 0.5, 0.05 center font ",9"
inslice(y) = (y > 0.03 && y < 0.07)
panel(name, what) = sprintf("%s: %s", what, system("cat " . dir . "/" . name . ".title"))
do for [run in "separators surface"] {
  layout = system("cat " . dir . "/" . run . ".layout")
  skip = int(word(layout, 1))
  n = int(word(layout, 2))
  what = (run eq "separators") ? "default (the separators)" : "-surface"
  set title panel(run, what)
  # gripper (label 0) as small squares, table (label 1) as dots; evaluated points drawn last
  file = dir . "/" . run . ".pcd"
  # a do-loop's body is parsed once, so the binary layout goes in through eval
  spec = sprintf('"%s" binary skip=%d record=%d format="%%float32%%float32%%float32%%float32%%uint32%%uint32"', file, skip, n)
  eval "plot " . spec . " using (($6 == 1 && inslice($2) && $4 != $4) ? $1 : 1/0):3:5 with points pt 7 ps 0.35 lc rgb variable, " . \
       spec . " using (($6 == 0 && inslice($2)) ? $1 : 1/0):3:5 with points pt 5 ps 0.45 lc rgb variable, " . \
       spec . " using (($6 == 1 && inslice($2) && $4 == $4) ? $1 : 1/0):3:5 with points pt 7 ps 0.7 lc rgb variable"
}
unset multiplot
