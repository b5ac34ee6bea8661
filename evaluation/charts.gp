# SPDX-License-Identifier: BSD-3-Clause
# Charts of the evaluation suite (issue #6), drawn from the driver's CSV files:
#
#   gnuplot -e "dir='docs/results'" evaluation/charts.gp
#
# reads  dir/{summary,queries,flips,model_size,reliability}.csv   (comma separated, header line)
# writes out/accuracy_vs_time.png, free_probability_vs_distance.png, flip_rate_vs_noise.png,
#        model_size_vs_accuracy.png, reliability.png, rescan_flips.png,
#        reliability_grid.png, signed_distance_vs_exact.png, hidden_collisions.png,
#        model_size_by_noise.png, query_time_by_noise.png
#                                                                     (out defaults to dir)
#
# Optional variables, given with -e before the script, e.g. -e "dir='x'; noise=1":
#   out       directory of the PNGs (default: dir)
#   wl        workload of charts 1-5: rows whose workload is exactly it (default 'W1', the dense
#             room; 'W1-sparse' the sparse one)
#   wlname    the workload as titles state it (default 'W1, piano in a room')
#   noise     noise level (% of the diagonal) of charts 1, 4 and 5 (default 0.5)
#   levels    noise levels of chart 2, e.g. '0.25 1 4' (default: every level found for ours)
#   ymetric   y of chart 1: 'auc' (default) or 'easy_accuracy'
#   baselines methods drawn as yes/no points in chart 2 (default 'octomap_2x nn_2sigma fcl_mesh')
#   msx       x of chart 4: 'nodes' (default) or 'leaf_pairs_mean'
#   noiseunit what noise_pct measures, for axis labels (default "% of the piano's bounding-box diagonal")
#   relband   band of chart 5: 'near_sigma' (|d| <= 2.8 sigma_eff, default), 'near_contact' or 'all'
#   gridwl    workloads of chart 7, one row each (default 'W1 W1-sparse W2 W3')
#   sizesettings  settings of ours in chart 10 (default 'classifier cloudmerge2 merge2 surface
#             surface-cloudmerge2'; those without rows are left out)
#   timesettings  method:setting series of chart 11 (default 'ours:classifier ours:cloudmerge2
#             ours:ladder ours:surface octomap_2x:mesh')
#   dwl, dlevels, dsetting  rows (default 'W1 W1-sparse'), noise levels (default: those up to 1 %
#             with a distance) and setting of ours (default 'surface') of chart 8
# Columns are found by header name, so the order of the columns does not matter. A chart whose
# file is missing or whose selection is empty is skipped with a message.

if (!exists("dir")) {
  print "charts.gp: give the CSV directory: gnuplot -e \"dir='docs/results'\" evaluation/charts.gp"
  exit status 1
}
if (!exists("out")) out = dir
if (!exists("wl")) wl = "W1"
if (!exists("wlname")) wlname = "W1, piano in a room"
if (!exists("noise")) noise = 0.5
noise = sprintf("%g", noise + 0)  # a number or a numeric string; awk gets it as text
if (!exists("ymetric")) ymetric = "auc"
if (!exists("baselines")) baselines = "octomap_2x nn_2sigma fcl_mesh"
if (!exists("msx")) msx = "nodes"
if (!exists("noiseunit")) noiseunit = "% of the piano's bounding-box diagonal"
if (!exists("relband")) relband = "near_sigma"
if (!exists("gridwl")) gridwl = "W1 W1-sparse W2 W3"

set encoding utf8
# The terminal of the single charts; charts 7 and 8 size it to their grids, chart 9 sets it back.
single_terminal = (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) \
  ? 'set terminal pngcairo size 900,600 noenhanced font "DejaVu Sans,11"' : 'set terminal png size 900,600 noenhanced'
eval single_terminal
set datafile separator "\t"
set datafile missing "nan"

# ---------------------------------------------------------------------------------------------
# Row selection with awk (mawk-compatible). Every program starts by mapping header names to
# column numbers (c["name"]) and drops a trailing CR; the caller's program then prints
# tab-separated fields. wl and the noise level reach awk as variables.

awk_prologue = "{ sub(/\\r$/, \"\") } NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next } "
awk_funcs = "function num(s) { return s ~ /^[-+]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][-+]?[0-9]+)?$/ } "
# Label placement for the labelled scatter charts: given points x[1..n], y[1..n] and labels
# l[1..n], sets the label anchors lx[i], ly[i]. A label goes right of its point, moved up or
# down by whole label heights until it overlaps no placed label and no other point. Sizes are
# in units of the data range (log x when logx), tuned to the 900x600 terminal and font 8.
awk_declutter = "function declutter(n, logx,   i, j, k, a, s, t, u, v, umin, umax, vmin, vmax, order, ok, \
    h, cw, w, b0, b1, c0, c1, m, pu0, pu1, pv0, pv1) { \
  h = 0.04; cw = 0.0095; \
  for (i = 1; i <= n; i++) { u[i] = logx ? log(x[i]) : x[i]; v[i] = y[i]; order[i] = i } \
  umin = umax = u[1]; vmin = vmax = v[1]; \
  for (i = 2; i <= n; i++) { if (u[i] < umin) umin = u[i]; if (u[i] > umax) umax = u[i]; \
                             if (v[i] < vmin) vmin = v[i]; if (v[i] > vmax) vmax = v[i] } \
  if (umax == umin) umax = umin + 1; if (vmax == vmin) vmax = vmin + 1; \
  for (i = 1; i <= n; i++) { u[i] = (u[i] - umin) / (umax - umin); v[i] = (v[i] - vmin) / (vmax - vmin) } \
  for (i = 2; i <= n; i++) { t = order[i]; for (j = i - 1; j >= 1 && v[order[j]] < v[t]; j--) order[j + 1] = order[j]; \
                             order[j + 1] = t } \
  m = 0; \
  for (k = 1; k <= n; k++) { \
    i = order[k]; w = length(l[i]) * cw; b0 = u[i] + 0.02; b1 = b0 + w; \
    for (a = 0; a <= 20; a++) { \
      s = (a % 2 ? -1 : 1) * int((a + 1) / 2) * h; c0 = v[i] + s - h / 2; c1 = v[i] + s + h / 2; ok = 1; \
      for (j = 1; j <= m && ok; j++) if (b0 < pu1[j] && b1 > pu0[j] && c0 < pv1[j] && c1 > pv0[j]) ok = 0; \
      for (j = 1; j <= n && ok; j++) if (j != i && u[j] > b0 - 0.008 && u[j] < b1 && v[j] > c0 && v[j] < c1) ok = 0; \
      if (ok) break } \
    if (!ok) { s = 0; c0 = v[i] - h / 2; c1 = v[i] + h / 2 } \
    m++; pu0[m] = b0; pu1[m] = b1; pv0[m] = c0; pv1[m] = c1; \
    lx[i] = logx ? exp(umin + b0 * (umax - umin)) : umin + b0 * (umax - umin); \
    ly[i] = vmin + (v[i] + s) * (vmax - vmin) } } "
select(file, level, prog) = sprintf("awk -F, -v OFS='\t' -v wl='%s' -v noise='%s' '%s%s%s%s' '%s/%s'", \
                                    wl, level, awk_funcs, awk_declutter, awk_prologue, prog, dir, file)
col(name) = sprintf("$c[\"%s\"]", name)
# Predicates on the current row.
is_wl = "$c[\"workload\"] == wl"
at_noise = "($c[\"noise_pct\"] - noise) * ($c[\"noise_pct\"] - noise) < 1e-12"

readable(file) = int(system(sprintf("test -r '%s/%s' && echo 1 || echo 0", dir, file)))
count(cmd) = int(system(cmd . " | wc -l"))
skip(chart, why) = sprintf("charts.gp: %s skipped: %s", chart, why)
png(name) = sprintf("%s/%s", out, name)

# Logistic function, without overflowing exp for large |z|.
logistic(z) = z >= 0 ? 1.0 / (1.0 + exp(-z)) : exp(z) / (1.0 + exp(z))

colours = "#1f77b4 #d62728 #2ca02c #9467bd #ff7f0e #17becf #8c564b #e377c2 #7f7f7f #bcbd22"
colour(i) = word(colours, (i - 1) % words(colours) + 1)

# ---------------------------------------------------------------------------------------------
# (1) Accuracy versus median query time, Pareto front marked. The front is computed here on the
# charted metric (x lower and y higher is better; a point is on it when no other point is at
# least as good in both and better in one), the definition of paretoFront() in metrics.h.

ylabel1 = (ymetric eq "auc") ? "ROC AUC over all queries" : "share of easy queries (|d| > 3σ) answered right"
front_prog = sprintf("%s && %s && num(%s) && num(%s) && %s > 0 { n++; x[n] = %s; y[n] = %s; l[n] = %s \":\" %s }", \
  is_wl, at_noise, col("median_us"), col(ymetric), col("median_us"), col("median_us"), col(ymetric), col("method"), col("setting")) \
  . " END { declutter(n, 1); for (i = 1; i <= n; i++) { on = 1; \
        for (j = 1; j <= n; j++) if (j != i && x[j] <= x[i] && y[j] >= y[i] && (x[j] < x[i] || y[j] > y[i])) on = 0; \
        print x[i], y[i], l[i], on, lx[i], ly[i] } }"
# Columns: x, y, label, on the front (1/0), label anchor x, y.
cmd1 = select("summary.csv", noise, front_prog)

if (!readable("summary.csv")) {
  print skip("accuracy_vs_time.png", "no summary.csv")
} else {
  if (count(cmd1) == 0) {
    print skip("accuracy_vs_time.png", sprintf("no %s rows at noise %s", wl, noise))
  } else {
    reset
    set output png("accuracy_vs_time.png")
    set title sprintf("%s, noise %s %%: %s versus median query time", wlname, noise, \
                      (ymetric eq "auc") ? "ROC AUC" : "easy-query accuracy")
    set logscale x
    set format x "%g"
    set xlabel "median query time (µs, prebuilt structures; log scale)"
    set ylabel ylabel1
    set grid
    set key bottom right
    set offsets graph 0.05, graph 0.25, graph 0.08, graph 0.05
    plot "< " . cmd1 using 1:2 with points pt 6 ps 1.3 lc rgb "#555555" title "method:setting", \
         "< " . cmd1 . " | awk -F'\t' '$4 == 1' | sort -t'\t' -g -k1,1" using 1:2 \
           with linespoints pt 7 ps 1.3 lw 2 lc rgb "#d62728" title "Pareto front", \
         "< " . cmd1 using 1:2:($5 - $1):($6 == $2 ? NaN : $6 - $2) with vectors nohead lw 0.5 lc rgb "#999999" notitle, \
         "< " . cmd1 using 5:6:3 with labels left font ",8" notitle
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (2) Collision-free probability (1 - score) of ours/default versus exact distance / sigma_eff,
# one colour and one logistic regression curve per noise level. The baselines' yes/no answers
# are drawn above 1 (free) and below 0 (not free), one row per method.
#
# The regression is P(free) = logistic(a + b d/sigma) by maximum likelihood (cross-entropy with
# the probabilities as soft labels), solved by damped Newton steps in awk. gnuplot's `fit`
# (least squares) is not used: on a clean separation, which is what a good method gives, the
# best slope is infinite and `fit` aborts the script with a singular matrix. A small ridge
# (0.01 b^2 / 2) keeps the slope finite there and changes nothing noticeable otherwise.
awk_logistic_fit = "function lg(z) { return z >= 0 ? 1 / (1 + exp(-z)) : exp(z) / (1 + exp(z)) } \
function softplus(z) { return z > 0 ? z + log(1 + exp(-z)) : log(1 + exp(z)) } \
function loss(a, b,   i, z, s) { s = 0.5 * (ra * a * a + rb * b * b); \
  for (i = 1; i <= n; i++) { z = a + b * x[i]; s += softplus(z) - y[i] * z } return s } \
{ n++; x[n] = $1; y[n] = $2 } \
END { ra = 1e-6; rb = 0.01; a = 0; b = 1; \
  for (it = 0; it < 200; it++) { \
    ga = ra * a; gb = rb * b; haa = ra; hab = 0; hbb = rb; \
    for (i = 1; i <= n; i++) { p = lg(a + b * x[i]); r = p - y[i]; w = p * (1 - p); \
      ga += r; gb += r * x[i]; haa += w; hab += w * x[i]; hbb += w * x[i] * x[i] } \
    det = haa * hbb - hab * hab; da = (hbb * ga - hab * gb) / det; db = (haa * gb - hab * ga) / det; \
    l0 = loss(a, b); t = 1; \
    while (t > 1e-9 && loss(a - t * da, b - t * db) > l0) t /= 2; \
    a -= t * da; b -= t * db; \
    if (t * (da * da + db * db) < 1e-20) break } \
  printf \"%.10g %.10g\\n\", a, b }"

ours_pred = sprintf("%s && %s == \"ours\" && %s == \"default\" && num(%s) && %s > 0 && num(%s) && num(%s)", \
  is_wl, col("method"), col("setting"), col("sigma_eff"), col("sigma_eff"), col("exact_distance"), col("score"))
cmd2(lv) = select("queries.csv", lv, sprintf("%s && %s { print %s / %s, 1 - %s }", \
  ours_pred, at_noise, col("exact_distance"), col("sigma_eff"), col("score")))
base_prog(m, k) = sprintf("%s && %s == \"%s\" && num(%s) && %s > 0 && num(%s) && num(%s) { f = 1 - %s; print %s / %s, f + (2 * f - 1) * 0.045 * %d }", \
  is_wl, col("method"), m, col("sigma_eff"), col("sigma_eff"), col("exact_distance"), col("score"), \
  col("score"), col("exact_distance"), col("sigma_eff"), k)
cmd2base(m, k) = select("queries.csv", noise, base_prog(m, k))

if (!readable("queries.csv")) {
  print skip("free_probability_vs_distance.png", "no queries.csv")
} else {
  if (!exists("levels")) {
    levels = system(select("queries.csv", noise, sprintf("%s { print %s }", ours_pred, col("noise_pct"))) \
                    . " | sort -gu | tr '\\n' ' '")
  }
  nlev = words(levels)
  if (nlev == 0) {
    print skip("free_probability_vs_distance.png", sprintf("no %s rows of ours/default", wl))
  } else {
    array FA[nlev]
    array FB[nlev]
    do for [i = 1:nlev] {
      lv = word(levels, i)
      FA[i] = NaN
      FB[i] = NaN
      if (count(cmd2(lv)) >= 5) {
        ab = system(cmd2(lv) . " | awk -F'\t' '" . awk_logistic_fit . "'")
        FA[i] = real(word(ab, 1))
        FB[i] = real(word(ab, 2))
        print sprintf("charts.gp: noise %s %%: P(free) = logistic(%.3g + %.3g d/σ), 1/2 at d = %.2g σ", \
                      lv, FA[i], FB[i], -FA[i] / FB[i])
      }
    }
    reset
    set output png("free_probability_vs_distance.png")
    set title sprintf("%s: P(free) of ours (default) versus exact distance / σ", wlname)
    set xlabel "exact signed distance / σ_eff   (negative = penetration)"
    set ylabel "P(free) = 1 - score"
    nb = words(baselines)
    set ytics ("0" 0, "0.25" 0.25, "0.5" 0.5, "0.75" 0.75, "1" 1)
    if (nb > 0) {
      set ytics add ("free" 1 + 0.045 * (nb + 1) / 2.0, "not free" -0.045 * (nb + 1) / 2.0)
    }
    set yrange [-0.045 * (nb + 1) : 1 + 0.045 * (nb + 1)]
    set grid
    # Inside, over the empty upper left (negative distances read as probably not free).
    set key at graph 0.02, graph 0.86 left top Left reverse box opaque font ",9" samplen 2
    set samples 400
    set arrow from graph 0, first 0 to graph 1, first 0 nohead dt 3 lc rgb "#999999"
    set arrow from graph 0, first 1 to graph 1, first 1 nohead dt 3 lc rgb "#999999"
    plot for [i = 1:nlev] "< " . cmd2(word(levels, i)) using 1:2 with points pt 7 ps 0.5 \
           lc rgb colour(i) title sprintf("ours, noise %s %%", word(levels, i)), \
         for [i = 1:nlev] logistic(FA[i] + FB[i] * x) with lines lw 2.5 lc rgb colour(i) \
           title sprintf("logistic regression, %s %%", word(levels, i)), \
         for [k = 1:words(baselines)] "< " . cmd2base(word(baselines, k), k) using 1:2 with points \
           pt (k + 3) ps 0.9 lc rgb "#444444" title word(baselines, k) . " (yes/no, all levels)"
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (3) Verdict flip rate (free versus not free, under noise re-sampling) versus noise level.

# Only the re-noise rows (kind renoise: the same samples, the noise re-drawn); chart 6 has the
# re-scans.
is_renoise = "(!(\"kind\" in c) || $c[\"kind\"] == \"renoise\")"
series_prog = sprintf("%s && %s { print %s \":\" %s }", is_wl, is_renoise, col("method"), col("setting"))
flip_prog(s) = sprintf("%s && %s && %s \":\" %s == \"%s\" && num(%s) && num(%s) { print %s, %s }", \
  is_wl, is_renoise, col("method"), col("setting"), s, col("noise_pct"), col("flip_rate"), col("noise_pct"), col("flip_rate"))
cmd3(s) = select("flips.csv", noise, flip_prog(s)) . " | sort -g -k1,1"

if (!readable("flips.csv")) {
  print skip("flip_rate_vs_noise.png", "no flips.csv")
} else {
  series = system(select("flips.csv", noise, series_prog) . " | awk '!seen[$0]++' | tr '\\n' ' '")
  if (words(series) == 0) {
    print skip("flip_rate_vs_noise.png", sprintf("no %s rows", wl))
  } else {
    reset
    set output png("flip_rate_vs_noise.png")
    set title sprintf("%s: verdict flip rate (free / not free) under noise re-draws, same samples", wlname)
    set xlabel sprintf("noise σ (%s; log scale)", noiseunit)
    set ylabel "flip rate (share of re-samples against the pose's majority)"
    flevels = system(select("flips.csv", noise, sprintf("%s && num(%s) && %s > 0 { print %s }", \
                     is_wl, col("noise_pct"), col("noise_pct"), col("noise_pct"))) . " | sort -gu | tr '\\n' ' '")
    set logscale x
    set xtics ()
    do for [lv in flevels] {
      set xtics add (lv lv + 0)
    }
    set xrange [(word(flevels, 1) + 0) / 1.4 : (word(flevels, words(flevels)) + 0) * 1.4]
    set yrange [0:*]
    set grid
    set key outside right center
    set offsets graph 0.05, graph 0.05, 0, 0
    plot for [i = 1:words(series)] "< " . cmd3(word(series, i)) using 1:2 with linespoints \
           lw 2 pt ((i - 1) % 13 + 1) dt 1 + int((i - 1) / words(colours)) lc rgb colour(i) title word(series, i)
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (4) Model size versus accuracy: one point per setting of ours at the chosen noise level.

# The easy-accuracy points take part in the label placement as unlabelled obstacles.
size_prog = sprintf("%s && %s && num(%s) && %s > 0 { n++; x[n] = %s; y[n] = %s; e[n] = %s; l[n] = %s }", \
  is_wl, at_noise, col(msx), col(msx), col(msx), col("auc"), col("easy_accuracy"), col("setting")) \
  . " END { k = n; for (i = 1; i <= k; i++) if (num(e[i])) { n++; x[n] = x[i]; y[n] = e[i]; l[n] = \"\" } \
            declutter(n, 1); for (i = 1; i <= k; i++) print x[i], y[i], e[i], l[i], lx[i], ly[i] }"
# Columns: size, AUC, easy accuracy, setting, label anchor x, y.
cmd4 = select("model_size.csv", noise, size_prog)

if (!readable("model_size.csv")) {
  print skip("model_size_vs_accuracy.png", "no model_size.csv")
} else {
  if (count(cmd4) == 0) {
    print skip("model_size_vs_accuracy.png", sprintf("no %s rows at noise %s", wl, noise))
  } else {
    reset
    set output png("model_size_vs_accuracy.png")
    set title sprintf("%s, noise %s %%: model size versus accuracy (ours, one point per setting)", wlname, noise)
    set xlabel (msx eq "nodes") ? "hierarchy nodes (log scale)" : "leaf classifiers fitted per query, mean (log scale)"
    set ylabel "accuracy"
    set logscale x
    set format x "%g"
    set grid
    set key bottom right
    set offsets graph 0.08, graph 0.15, graph 0.08, graph 0.08
    plot "< " . cmd4 using 1:2 with points pt 7 ps 1.4 lc rgb "#1f77b4" title "ROC AUC over all queries", \
         "< " . cmd4 using 1:3 with points pt 4 ps 1.4 lc rgb "#d62728" title "easy-query accuracy", \
         "< " . cmd4 using 1:2:($5 - $1):($6 == $2 ? NaN : $6 - $2) with vectors nohead lw 0.5 lc rgb "#999999" notitle, \
         "< " . cmd4 using 5:6:4 with labels left font ",8" notitle
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (5) Reliability diagram of ours: default, classifier, surface and max (the paper's),
# over the near-contact queries; point area follows the bin count, empty bins are left out.

in_band(b) = sprintf("(!(\"band\" in c) || $c[\"band\"] == \"%s\")", b)
rel_prog(s) = sprintf("%s && %s && %s && %s == \"ours\" && %s == \"%s\" && %s > 0 && num(%s) && num(%s) { print %s, %s, %s }", \
  is_wl, at_noise, in_band(relband), col("method"), col("setting"), s, col("count"), col("mean_predicted"), col("observed"), \
  col("mean_predicted"), col("observed"), col("count"))
cmd5(s) = select("reliability.csv", noise, rel_prog(s)) . " | sort -g -k1,1"
brier_col = (relband eq "near_sigma") ? "brier_near_sigma" : "brier_near"
brier_prog(s) = sprintf("%s && %s && %s == \"ours\" && %s == \"%s\" && num(%s) { printf \"%%.3f\", %s; exit }", \
  is_wl, at_noise, col("method"), col("setting"), s, col(brier_col), col(brier_col))
brier(s) = readable("summary.csv") ? system(select("summary.csv", noise, brier_prog(s))) : ""
rel_title(s) = strlen(brier(s)) > 0 ? sprintf("ours, %s (Brier %s)", s, brier(s)) : sprintf("ours, %s", s)
max_count(s) = real(system(cmd5(s) . " | awk -F'\t' 'BEGIN { m = 0 } $3 > m { m = $3 } END { print m }'"))

if (!readable("reliability.csv")) {
  print skip("reliability.png", "no reliability.csv")
} else {
  if (count(cmd5("default")) + count(cmd5("max")) == 0) {
    print skip("reliability.png", sprintf("no ours/default or ours/max rows of %s at noise %s", wl, noise))
  } else {
    biggest = max_count("default") > max_count("max") ? max_count("default") : max_count("max")
    biggest = max_count("classifier") > biggest ? max_count("classifier") : biggest
    biggest = max_count("surface") > biggest ? max_count("surface") : biggest
    reset
    set output png("reliability.png")
    bandname = (relband eq "near_sigma") ? "|d| <= 2.8 σ_eff" : (relband eq "near_contact") ? "near-contact queries" : "all queries"
    set title sprintf("%s, noise %s %%: reliability of the collision probability (%s)", wlname, noise, bandname)
    set xlabel "mean predicted collision probability in the bin"
    set ylabel "observed collision frequency"
    set xrange [0:1]
    set yrange [0:1]
    set size ratio -1
    set grid
    set key top left box
    set label "marker area grows with the bin's count; empty bins left out" at graph 0.98, graph 0.04 right font ",9"
    plot x with lines dt 2 lw 1.5 lc rgb "#777777" title "perfect calibration", \
         "< " . cmd5("default") using 1:2:(0.6 + 2.4 * sqrt($3 / biggest)) with linespoints pt 7 ps variable \
           lw 2 lc rgb "#1f77b4" title rel_title("default"), \
         "< " . cmd5("classifier") using 1:2:(0.6 + 2.4 * sqrt($3 / biggest)) with linespoints pt 9 ps variable \
           lw 2 lc rgb "#2ca02c" title rel_title("classifier"), \
         "< " . cmd5("surface") using 1:2:(0.6 + 2.4 * sqrt($3 / biggest)) with linespoints pt 11 ps variable \
           lw 2 lc rgb "#ff7f0e" title rel_title("surface"), \
         "< " . cmd5("max") using 1:2:(0.6 + 2.4 * sqrt($3 / biggest)) with linespoints pt 5 ps variable \
           lw 2 lc rgb "#d62728" title rel_title("max")
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (6) Stability by re-scan (issue 16): any-flip rate of the free / not-free verdict over the
# re-scans (new sample positions and new noise) against the noise level, per room density
# (solid: W1, the dense room; dashed: W1-sparse), for ours and the 2-sigma collision map.

scan_series = "ours:default ours:classifier ours:surface octomap_2x:mesh"
scan_prog(w, s) = sprintf("$c[\"workload\"] == \"%s\" && $c[\"kind\"] == \"rescan\" && %s \":\" %s == \"%s\" && num(%s) && num(%s) { print %s, %s }", \
  w, col("method"), col("setting"), s, col("noise_pct"), col("any_flip_rate"), col("noise_pct"), col("any_flip_rate"))
cmd6(w, s) = select("flips.csv", noise, scan_prog(w, s)) . " | sort -g -k1,1"

if (!readable("flips.csv")) {
  print skip("rescan_flips.png", "no flips.csv")
} else {
  if (count(select("flips.csv", noise, "$c[\"kind\"] == \"rescan\" { print }")) == 0) {
    print skip("rescan_flips.png", "no re-scan rows")
  } else {
    reset
    set output png("rescan_flips.png")
    set title "W1: any-flip rate of the verdict over re-scans (new samples, new noise), |d| <= 2.8 σ_eff"
    set xlabel sprintf("noise σ (%s; log scale)", noiseunit)
    set ylabel "share of poses whose free / not-free verdict changes"
    slevels = system(select("flips.csv", noise, sprintf("$c[\"kind\"] == \"rescan\" && num(%s) && %s > 0 { print %s }", \
                     col("noise_pct"), col("noise_pct"), col("noise_pct"))) . " | sort -gu | tr '\\n' ' '")
    set logscale x
    set xtics ()
    do for [lv in slevels] {
      set xtics add (lv lv + 0)
    }
    set xrange [(word(slevels, 1) + 0) / 1.4 : (word(slevels, words(slevels)) + 0) * 1.4]
    set yrange [0:1]
    set grid
    set key outside right center
    plot for [i = 1:words(scan_series)] "< " . cmd6("W1", word(scan_series, i)) using 1:2 with linespoints \
           lw 2 pt 7 dt 1 lc rgb colour(i) title "dense: " . word(scan_series, i), \
         for [i = 1:words(scan_series)] "< " . cmd6("W1-sparse", word(scan_series, i)) using 1:2 with linespoints \
           lw 2 pt 6 dt 2 lc rgb colour(i) title "sparse: " . word(scan_series, i)
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (7) Reliability per workload (rows: gridwl) and noise level (columns), ours classifier and
# surface (one of them is the default). W1 and W2 over the near band |d| <= 2.8 σ_eff; W3 over all its queries against
# "listed as not free". Filled markers: bins of >= 30 queries, judged by issue 16's check (red
# ring: outside max(0.1, 2 binomial SE)); open markers: smaller bins.

grid_band(w) = (w eq "W3") ? "all" : "near_sigma"
grid_prog(w, lv, s, judged) = sprintf("$c[\"workload\"] == \"%s\" && ($c[\"noise_pct\"] - %s) * ($c[\"noise_pct\"] - %s) < 1e-12 && $c[\"band\"] == \"%s\" && %s == \"ours\" && %s == \"%s\" && %s > 0 && num(%s) && num(%s) && $c[\"judged\"] == %d { print %s, %s, %s, $c[\"within\"] }", \
  w, lv, lv, grid_band(w), col("method"), col("setting"), s, col("count"), col("mean_predicted"), col("observed"), judged, \
  col("mean_predicted"), col("observed"), col("count"))
cmd7(w, lv, s, judged) = select("reliability.csv", noise, grid_prog(w, lv, s, judged))
grid_levels(w) = system(select("reliability.csv", noise, sprintf("$c[\"workload\"] == \"%s\" && %s == \"ours\" { print %s }", \
                        w, col("method"), col("noise_pct"))) . " | sort -gu | tr '\\n' ' '")

if (!readable("reliability.csv")) {
  print skip("reliability_grid.png", "no reliability.csv")
} else {
  rows = ""
  ncols = 0
  do for [w in gridwl] {
    if (words(grid_levels(w)) > 0) {
      rows = rows . " " . w
      ncols = words(grid_levels(w)) > ncols ? words(grid_levels(w)) : ncols
    }
  }
  nrows = words(rows)
  if (nrows == 0) {
    print skip("reliability_grid.png", "no rows of ours")
  } else {
    reset
    if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
      set terminal pngcairo size (ncols > 2 ? 300 * ncols + 60 : 720), 300 * nrows + 60 noenhanced font "DejaVu Sans,9"
    } else {
      set terminal png size (ncols > 2 ? 300 * ncols + 60 : 720), 300 * nrows + 60 noenhanced
    }
    set output png("reliability_grid.png")
    set multiplot layout nrows, ncols title "Reliability of P (green: classifier, orange: surface; filled: bin of >= 30, judged; red ring: outside)"
    set xrange [0:1]
    set yrange [0:1]
    set size ratio -1
    set grid
    set xtics 0.5
    set ytics 0.5
    unset key
    do for [r = 1:nrows] {
      w = word(rows, r)
      lvls = grid_levels(w)
      do for [k = 1:ncols] {
        if (k <= words(lvls)) {
          lv = word(lvls, k)
          set title sprintf("%s, noise %s (%s)", w, lv, grid_band(w))
          plot x with lines dt 2 lc rgb "#777777", \
               "< " . cmd7(w, lv, "surface", 0) using 1:2 with points pt 6 ps 0.8 lc rgb "#ff7f0e", \
               "< " . cmd7(w, lv, "classifier", 0) using 1:2 with points pt 8 ps 0.8 lc rgb "#2ca02c", \
               "< " . cmd7(w, lv, "surface", 1) using 1:2 with points pt 7 ps 1.3 lc rgb "#ff7f0e", \
               "< " . cmd7(w, lv, "classifier", 1) using 1:2 with points pt 9 ps 1.3 lc rgb "#2ca02c", \
               "< " . cmd7(w, lv, "surface", 1) . " | awk -F'\t' '$4 == 0'" using 1:2 with points pt 6 ps 2.2 lw 2 lc rgb "#d62728", \
               "< " . cmd7(w, lv, "classifier", 1) . " | awk -F'\t' '$4 == 0'" using 1:2 with points pt 6 ps 2.2 lw 2 lc rgb "#d62728"
        } else {
          set multiplot next
        }
      }
    }
    unset multiplot
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (8) The surface layer's signed distance against the exact one, both in σ_eff, for the poses
# within 5 σ_eff of contact: one panel per room (rows, dwl) and noise level (columns, dlevels),
# error bars ±2 std; blue: the interval covers the exact distance, red: it misses. The titles
# give the coverage of the near band (between the dotted lines), as issue 16's target counts
# it (targets.csv). Colliding poses answered in
# decision mode report the first deciding point's distance (docs/SURFACE.md, step 5).

if (!exists("dwl")) dwl = "W1 W1-sparse"
if (!exists("dsetting")) dsetting = "surface"
# The levels of the coverage target (0.25-1 %) at which the setting gave a distance.
if (!exists("dlevels") && readable("queries.csv")) {
  dlevels = system(select("queries.csv", noise, sprintf("%s == \"ours\" && %s == \"%s\" && %s ~ /^W1/ && num(%s) && %s > 0 && %s <= 1 { print %s }", \
                   col("method"), col("setting"), dsetting, col("workload"), col("signed_distance"), col("noise_pct"), \
                   col("noise_pct"), col("noise_pct"))) \
                   . " | sort -gu | tr '\\n' ' '")
}
near8 = 2.8  # the near band, |d| <= 2.8 σ_eff (evaluate_collision's kNearSigma)
shown8 = 5   # the poses plotted, |d| <= 5 σ_eff
dist_prog(w, lv, covered, reach) = sprintf("$c[\"workload\"] == \"%s\" && ($c[\"noise_pct\"] - %s) * ($c[\"noise_pct\"] - %s) < 1e-12 && %s == \"ours\" && %s == \"%s\" && num(%s) && num(%s) && %s > 0 { s = %s; e = %s / s; d = %s / s; u = %s / s; if (e < -%g || e > %g) next; ok = (d - e <= 2 * u && e - d <= 2 * u); if (ok == %d) print e, d, 2 * u }", \
  w, lv, lv, col("method"), col("setting"), dsetting, col("signed_distance"), col("signed_distance_std"), col("sigma_eff"), \
  col("sigma_eff"), col("exact_distance"), col("signed_distance"), col("signed_distance_std"), reach, reach, covered)
cmd8(w, lv, covered, reach) = select("queries.csv", noise, dist_prog(w, lv, covered, reach))

if (!readable("queries.csv")) {
  print skip("signed_distance_vs_exact.png", "no queries.csv")
} else {
  drows = ""
  do for [w in dwl] {
    n8 = 0
    do for [lv in dlevels] { n8 = n8 + count(cmd8(w, lv, 1, shown8)) + count(cmd8(w, lv, 0, shown8)) }
    if (n8 > 0) { drows = drows . " " . w }
  }
  if (words(drows) == 0) {
    print skip("signed_distance_vs_exact.png", sprintf("no signed distances of ours/%s", dsetting))
  } else {
    reset
    nc8 = words(dlevels)
    if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
      set terminal pngcairo size 420 * nc8 + 60, 400 * words(drows) + 60 noenhanced font "DejaVu Sans,9"
    } else {
      set terminal png size 420 * nc8 + 60, 400 * words(drows) + 60 noenhanced
    }
    set output png("signed_distance_vs_exact.png")
    set multiplot layout words(drows), nc8 title sprintf("ours/%s: signed distance ±2 std against the exact one, in σ_eff (blue: covers it, red: misses)", dsetting)
    set xrange [-shown8:shown8]
    set yrange [-8:8]
    set grid
    set xlabel "exact signed distance / σ_eff"
    set ylabel "estimated / σ_eff"
    unset key
    set arrow 1 from first -near8, graph 0 to first -near8, graph 1 nohead dt 3 lc rgb "#999999"
    set arrow 2 from first near8, graph 0 to first near8, graph 1 nohead dt 3 lc rgb "#999999"
    do for [w in drows] {
      do for [lv in dlevels] {
        n_in = count(cmd8(w, lv, 1, near8))
        n_out = count(cmd8(w, lv, 0, near8))
        set title sprintf("%s, noise %s %%: %.3f of %d near-band poses covered", w, lv, \
                          n_in + n_out > 0 ? 1.0 * n_in / (n_in + n_out) : 0, n_in + n_out)
        plot x with lines dt 2 lc rgb "#777777", \
             "< " . cmd8(w, lv, 1, shown8) using 1:2:3 with yerrorbars pt 7 ps 0.4 lc rgb "#a01f77b4", \
             "< " . cmd8(w, lv, 0, shown8) using 1:2:3 with yerrorbars pt 7 ps 0.5 lc rgb "#d62728"
      }
    }
    unset multiplot
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (9) Hidden collisions (issue 16): the share of near-band "free" answers (P < 0.1, |d| <= 2.8
# σ_eff) that collide, the error a planner pays for, against the noise level, per room density
# (solid: W1, the dense room; dashed: W1-sparse), for ours and the 2-sigma collision maps. A cell
# without a free answer has no share and no point. Dotted: issue 16's target, at most 5 %.

hidden_series = "ours:classifier ours:surface ours:pooled ours:ladder octomap_2x:mesh octomap_2x:cloud"
hidden_prog(w, s) = sprintf("$c[\"workload\"] == \"%s\" && %s \":\" %s == \"%s\" && num(%s) && num(%s) && %s > 0 && %s > 0 { print %s, %s }", \
  w, col("method"), col("setting"), s, col("noise_pct"), col("hidden_rate_near_sigma"), col("noise_pct"), \
  col("free_near_sigma"), col("noise_pct"), col("hidden_rate_near_sigma"))
cmd9(w, s) = select("summary.csv", noise, hidden_prog(w, s)) . " | sort -g -k1,1"
hidden_rows(s) = count(cmd9("W1", s)) + count(cmd9("W1-sparse", s))

if (!readable("summary.csv")) {
  print skip("hidden_collisions.png", "no summary.csv")
} else {
  hseries = ""
  do for [s in hidden_series] {
    if (hidden_rows(s) > 0) { hseries = hseries . " " . s }
  }
  if (words(hseries) == 0) {
    print skip("hidden_collisions.png", "no W1 row with a near-band free answer")
  } else {
    reset
    eval single_terminal
    set output png("hidden_collisions.png")
    set title "W1: share of the near-band \"free\" answers (P < 0.1, |d| <= 2.8 σ_eff) that collide\n(ours:classifier is the default)"
    set xlabel sprintf("noise σ (%s; log scale)", noiseunit)
    set ylabel "hidden collisions / free answers"
    hlevels = system(select("summary.csv", noise, sprintf("%s ~ /^W1/ && num(%s) && %s > 0 { print %s }", \
                     col("workload"), col("noise_pct"), col("noise_pct"), col("noise_pct"))) . " | sort -gu | tr '\\n' ' '")
    set logscale x
    set xtics ()
    do for [lv in hlevels] {
      set xtics add (lv lv + 0)
    }
    set xrange [(word(hlevels, 1) + 0) / 1.4 : (word(hlevels, words(hlevels)) + 0) * 1.4]
    set yrange [0:*]
    set grid
    set key outside right center
    plot 0.05 with lines dt 3 lw 2 lc rgb "#555555" title "target: 5 %", \
         for [i = 1:words(hseries)] "< " . cmd9("W1", word(hseries, i)) using 1:2 with linespoints \
           lw 2 pt 7 dt 1 lc rgb colour(i) title "dense: " . word(hseries, i), \
         for [i = 1:words(hseries)] "< " . cmd9("W1-sparse", word(hseries, i)) using 1:2 with linespoints \
           lw 2 pt 6 dt 2 lc rgb colour(i) title "sparse: " . word(hseries, i)
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (10) Model size and work against accuracy at every noise level (issue #17, item 1): for each
# setting of sizesettings, one line through its noise levels, hierarchy nodes (left) and leaf
# pairs tested per query (right) against the ROC AUC over all queries, each point
# labelled with its noise level. A setting whose resolution follows the noise keeps its line
# from running right as the noise grows. Workload wl, model_size.csv.

if (!exists("sizesettings")) sizesettings = "classifier cloudmerge2 merge2 surface surface-cloudmerge2"
size_noise_prog(s) = sprintf("%s && %s == \"%s\" && num(%s) && num(%s) && num(%s) && %s > 0 && %s > 0 { print %s, %s, %s, %s }", \
  is_wl, col("setting"), s, col("noise_pct"), col("nodes"), col("leaf_pairs_mean"), col("nodes"), col("leaf_pairs_mean"), \
  col("noise_pct"), col("nodes"), col("leaf_pairs_mean"), col("auc"))
# Columns: noise, nodes, leaf pairs per query, AUC; in noise order.
cmd10(s) = select("model_size.csv", noise, size_noise_prog(s)) . " | sort -g -k1,1"

if (!readable("model_size.csv")) {
  print skip("model_size_by_noise.png", "no model_size.csv")
} else {
  sseries = ""
  do for [s in sizesettings] {
    if (count(cmd10(s)) > 0) { sseries = sseries . " " . s }
  }
  if (words(sseries) == 0) {
    print skip("model_size_by_noise.png", sprintf("no %s rows of %s", wl, sizesettings))
  } else {
    reset
    if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
      set terminal pngcairo size 1400,620 noenhanced font "DejaVu Sans,11"
    } else {
      set terminal png size 1400,620 noenhanced
    }
    set output png("model_size_by_noise.png")
    set multiplot layout 1,2 title sprintf("%s: model size and leaf pairs tested against ROC AUC at every noise level (labels: noise, %% of the diagonal)", wlname)
    set logscale x
    set format x "%g"
    set ylabel "ROC AUC over all queries"
    set grid
    set key bottom left
    set offsets graph 0.05, graph 0.1, graph 0.05, graph 0.05
    set xlabel "hierarchy nodes, both clouds (log scale)"
    plot for [i = 1:words(sseries)] "< " . cmd10(word(sseries, i)) using 2:4 with linespoints \
           lw 2 pt 7 ps 1.2 lc rgb colour(i) title word(sseries, i), \
         for [i = 1:words(sseries)] "< " . cmd10(word(sseries, i)) using 2:4:(sprintf(" %g", $1)) with labels \
           left offset 0.3, 0.3 font ",8" tc rgb colour(i) notitle
    set xlabel "leaf pairs tested per query, mean (log scale)"
    set key off
    plot for [i = 1:words(sseries)] "< " . cmd10(word(sseries, i)) using 3:4 with linespoints \
           lw 2 pt 7 ps 1.2 lc rgb colour(i) title word(sseries, i), \
         for [i = 1:words(sseries)] "< " . cmd10(word(sseries, i)) using 3:4:(sprintf(" %g", $1)) with labels \
           left offset 0.3, 0.3 font ",8" tc rgb colour(i) notitle
    unset multiplot
    unset output
  }
}

# ---------------------------------------------------------------------------------------------
# (11) Query time against the noise level (issue #17's speed targets): median (solid) and max
# (dashed) query time per setting, the dense room left and the sparse one right (workloads
# W1 and W1-sparse), with the targets: the max at most 5 ms at 2 and 4 %, and the median at
# 2-4 % no higher than at 0.5 % (dotted, the first setting's median at 0.5 %, in its colour).

if (!exists("timesettings")) timesettings = "ours:classifier ours:cloudmerge2 ours:ladder ours:surface octomap_2x:mesh"
time_prog(w, s, what) = sprintf("$c[\"workload\"] == \"%s\" && %s \":\" %s == \"%s\" && num(%s) && num(%s) && %s > 0 && %s > 0 { print %s, %s / 1000 }", \
  w, col("method"), col("setting"), s, col("noise_pct"), col(what), col("noise_pct"), col(what), col("noise_pct"), col(what))
cmd11(w, s, what) = select("summary.csv", noise, time_prog(w, s, what)) . " | sort -g -k1,1"
median_at(w, s) = system(cmd11(w, s, "median_us") . " | awk -F'\t' '$1 == 0.5 { print $2; exit }'")

if (!readable("summary.csv")) {
  print skip("query_time_by_noise.png", "no summary.csv")
} else {
  tseries = ""
  do for [s in timesettings] {
    if (count(cmd11("W1", s, "median_us")) + count(cmd11("W1-sparse", s, "median_us")) > 0) { tseries = tseries . " " . s }
  }
  if (words(tseries) == 0) {
    print skip("query_time_by_noise.png", "no W1 rows of " . timesettings)
  } else {
    reset
    if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
      set terminal pngcairo size 1400,740 noenhanced font "DejaVu Sans,11"
    } else {
      set terminal png size 1400,740 noenhanced
    }
    set output png("query_time_by_noise.png")
    set multiplot layout 1,2 title "Query time against the noise level (one thread; solid: median, dashed: max; dotted: issue #17's targets)"
    tlevels = system(select("summary.csv", noise, sprintf("%s ~ /^W1/ && num(%s) && %s > 0 { print %s }", \
                     col("workload"), col("noise_pct"), col("noise_pct"), col("noise_pct"))) . " | sort -gu | tr '\\n' ' '")
    set logscale xy
    set format y "%g"
    set xtics ()
    do for [lv in tlevels] {
      set xtics add (lv lv + 0)
    }
    set xrange [(word(tlevels, 1) + 0) / 1.4 : (word(tlevels, words(tlevels)) + 0) * 1.4]
    set xlabel sprintf("noise σ (%s; log scale)", noiseunit)
    set ylabel "query time (ms, log scale)"
    set grid
    do for [w in "W1 W1-sparse"] {
      set title (w eq "W1") ? "dense room (W1)" : "sparse room (W1-sparse)"
      m05 = median_at(w, word(tseries, 1))
      set key below horizontal maxrows 4 font ",9"  # both panels, so that their plot areas match
      plot (x >= 2 ? 5 : NaN) with lines dt 3 lw 2 lc rgb "#555555" title "target: max 5 ms", \
           (strlen(m05) > 0 && x >= 2 ? m05 + 0 : NaN) with lines dt 3 lw 2 lc rgb colour(1) \
             title "target: median at 0.5 %", \
           for [i = 1:words(tseries)] "< " . cmd11(w, word(tseries, i), "median_us") using 1:2 with linespoints \
             lw 2 pt 7 dt 1 lc rgb colour(i) title word(tseries, i), \
           for [i = 1:words(tseries)] "< " . cmd11(w, word(tseries, i), "max_us") using 1:2 with linespoints \
             lw 1 pt 6 dt 2 lc rgb colour(i) notitle
    }
    unset multiplot
    unset output
  }
}
