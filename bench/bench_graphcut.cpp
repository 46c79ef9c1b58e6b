// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: graph-cut synthesis (texture/graphcut_synthesis.h) against G'MIC's
// `syntexturize_matchpatch` on every texture of shared/data/textures, 256x256
// output; plus a 128x128 periodic tile per texture and its wrap-seam ratio.
//
// Similarity: texture/bidirectional_similarity.h (Simakov et al. 2008) with a
// fixed setting for every texture and both methods: 7x7 patches, output
// patches at stride 2, exemplar patches at every position (non-periodic),
// exact nearest neighbours (max_candidates = 0). bds = coherence +
// completeness, mean squared difference per value (lower is better).
// Alpha is kept: both outputs are compared with the exemplar's channels.
//
// Usage: bench_graphcut [TEXTURE_DIR] [WORK_DIR] [NAME,NAME,...|-] [GMIC_RUNS] [TILE_SIZE] [MODE]
//                       [STRAIGHT_SEAM_STEPS] [STRAIGHT_SEAM_COST_TOLERANCE]
// The optional list keeps only the textures whose file stem is listed ("-" =
// all). MODE: all (default), synthesis (no tile) or tile (no 256 synthesis,
// no G'MIC). The last two override TileOptions::straight_seam_steps (0 = the
// tiles without the straight-seam repair) and straight_seam_cost_tolerance. G'MIC (from PATH; if it is missing or GMIC_RUNS is 0 the G'MIC
// fields are absent) is
// unseeded, so it runs GMIC_RUNS times (default 3) per texture and ours is
// compared with the median of its similarity scores and the median of its
// wall and CPU times (each run includes G'MIC's process start and PNG IO,
// ours excludes IO). TILE_SIZE (default 128) is the side of the periodic
// tile. One JSON line per texture, then a summary.
//
// Results (lead: re-measure on a quiet machine). Run of 2026-11-22 06:51-07:37,
// load average 4-10 on 2 cores (5 engineers), so wall times are inflated and
// CPU seconds are more telling; G'MIC 3 runs per texture, median compared.
// Graph-cut: automatic patch side fitted to the fill grid (154 px on a 256
// output instead of 192 px overlapping by 128). tile128 = default 128x128
// periodic tile, seed 1 (measured for all 29 separately with the same code).
// Summary: bds no worse than the G'MIC median on 23/29; our CPU below G'MIC's median on 29/29
// (79.3%, goal 80%: losses are within 1-3% of the median except ink_a_400, +19%);
// summed wall ratio ours/G'MIC 0.11, CPU 0.09; tiles with ratio <= 1.3: 27/29.
//   texture                    ours wall/cpu  gmic median wall/cpu  bds ours  gmic median [min-max of 3]        tile128 ratio (seam cost)
// box_tree_leaves_256          0.53/0.21      6.83/3.36          0.01362 0.01458 [0.01402-0.01464] ok    1.105 (135.7)
// brick_gray_512               0.34/0.18      1.53/0.56          0.00030 0.00032 [0.00031-0.00032] ok    0.878 (15.1)
// brick_small_96               0.34/0.17     18.74/6.27          0.00664 0.01212 [0.01182-0.01212] ok    0.946 (270.4)
// bricks_with_hole_rgba_350    0.38/0.14      3.76/1.16          0.00206 0.00209 [0.00209-0.00441] ok    1.131 (128.4)
// burlap_96                    0.63/0.20      6.53/2.56          0.00256 0.00554 [0.00546-0.00555] ok    0.924 (160.7)
// cane_weave_rgba_128          0.31/0.15      7.16/2.32          0.00047 0.00114 [0.00107-0.00123] ok    0.783 (66.6)
// chainmail_512                1.87/0.38      3.27/0.90          0.00199 0.00217 [0.00201-0.00218] ok    1.128 (89.3)
// coffee_beans_64              0.88/0.21      2.70/0.90          0.00088 0.00258 [0.00256-0.00259] ok    1.027 (175.5)
// cracked_mud_100              0.42/0.21      3.91/0.83          0.00259 0.00440 [0.00430-0.00443] ok    0.969 (149.3)
// denim_256                    1.33/0.25      2.24/0.56          0.00829 0.00980 [0.00965-0.01000] ok    0.961 (83.9)
// dots_large_208x168           0.72/0.10     10.39/2.05          0.00012 0.00080 [0.00077-0.00088] ok    1.597 (0.0)
// dots_purple_354x352          0.41/0.09      6.84/2.27          0.00017 0.00082 [0.00081-0.00082] ok    0.887 (0.0)
// drawn_dots_512               1.33/0.22      1.85/0.61          0.00625 0.00620 [0.00580-0.00680] LOSS  1.135 (58.1)
// fabric_brown_256             0.75/0.19      3.38/1.43          0.00043 0.00045 [0.00045-0.00046] ok    0.956 (18.6)
// grass_gray_512               0.44/0.23      2.36/1.27          0.00743 0.00781 [0.00761-0.00786] ok    0.875 (45.4)
// gravel_gray_512              0.20/0.20      0.34/0.40          0.00417 0.00411 [0.00403-0.00438] LOSS  1.015 (51.4)
// ink_a_400                    0.18/0.17      1.51/0.91          0.00343 0.00289 [0.00269-0.00302] LOSS  1.105 (95.7)
// ink_b_400                    0.31/0.21      5.58/4.63          0.00260 0.00809 [0.00434-0.00865] ok    0.935 (15.2)
// leather_64                   0.20/0.20     13.53/13.38          0.00046 0.00136 [0.00135-0.00138] ok    1.110 (122.7)
// pebbles_256                  0.18/0.18      6.86/5.94          0.01151 0.01293 [0.01265-0.01379] ok    0.838 (124.9)
// red_checked_384              0.26/0.25      0.86/0.83          0.00041 0.00041 [0.00041-0.00044] ok    0.282 (10.8)
// reptile_skin_512             0.20/0.20      1.45/1.03          0.00144 0.00142 [0.00137-0.00151] LOSS  0.776 (64.4)
// rock_512                     0.44/0.31      5.04/4.60          0.00221 0.00220 [0.00214-0.00224] LOSS  0.883 (49.6)
// stripes_blue_white_256       0.04/0.04      0.50/0.46          0.00000 0.00063 [0.00000-0.00089] ok    0.000 (0.0)
// teddy_fur_256                0.16/0.18      0.53/0.46          0.00101 0.00119 [0.00117-0.00126] ok    1.043 (12.1)
// tree_bark_512                0.25/0.25      1.17/1.15          0.00932 0.01029 [0.00966-0.01083] ok    0.919 (137.1)
// water_caustics_300           0.13/0.15      0.35/0.46          0.00104 0.00110 [0.00101-0.00111] ok    1.707 (37.8)
// wood_512                     0.30/0.29      0.94/0.88          0.00031 0.00034 [0.00033-0.00035] ok    0.639 (21.8)
// woven_tissue_512             0.22/0.21      0.54/0.54          0.00290 0.00282 [0.00281-0.00316] LOSS  0.752 (23.5)
//
// Session 4 (2026-11-22 09:40-10:10, load average 6-8 on 2 cores): error-region
// refinement with sub-patch matching, the repetition term (GraphcutOptions::
// repetition_penalty 0.3) and the torus cut of tiles (TileOptions::choose_cut).
// Our side measured with this benchmark's setting (seed 1, 256 output, same
// similarity) by a driver without G'MIC; G'MIC's medians are those of the
// run above (its output does not depend on our code). bds no worse than the
// G'MIC median: 26/29 (before: 23/29); losses drawn_dots +0.9%, gravel +1.4%,
// woven_tissue +2.7%, each inside G'MIC's own min-max over 3 runs. Our CPU
// seconds summed 5.72 (before 4.59) against G'MIC's 62.74 (ratio 0.09); the
// highest per-texture ratio 0.49 (gravel). Tiles (128 px, seed 1,
// repetition_penalty 0): wrap-seam ratio <= 1.3 at the synthesis cut 26/29
// (dots_large 1.60, ink_a 1.51, water_caustics 1.74), after the roll onto
// the smoothest row and column 29/29 (biased low by construction: the
// minimum over the torus lines, see texture/tileable_tile.h).
//   texture                    cpu   bds before  bds now   gmic median  now vs gmic   tile128 ratio synthesis cut -> rolled (seam cost)
// box_tree_leaves_256        0.22  0.01362    0.01272   0.01458      ok    -12.7%   1.110 -> 0.705 (181.1)
// brick_gray_512             0.18  0.00030    0.00030   0.00032      ok     -6.2%   0.903 -> 0.169 (15.5)
// brick_small_96             0.17  0.00664    0.00655   0.01212      ok    -45.9%   0.886 -> 0.532 (255.0)
// bricks_with_hole_rgba_350  0.13  0.00206    0.00206   0.00209      ok     -1.1%   1.145 -> 0.349 (119.6)
// burlap_96                  0.19  0.00256    0.00236   0.00554      ok    -57.5%   0.960 -> 0.415 (165.5)
// cane_weave_rgba_128        0.13  0.00047    0.00047   0.00114      ok    -59.0%   0.291 -> 0.173 (23.7)
// chainmail_512              0.28  0.00199    0.00198   0.00217      ok     -9.0%   1.204 -> 0.387 (79.9)
// coffee_beans_64            0.19  0.00088    0.00086   0.00258      ok    -66.7%   1.056 -> 0.723 (173.2)
// cracked_mud_100            0.17  0.00259    0.00251   0.00440      ok    -42.9%   1.029 -> 0.666 (150.7)
// denim_256                  0.21  0.00829    0.00789   0.00980      ok    -19.5%   1.060 -> 0.746 (91.9)
// dots_large_208x168         0.08  0.00012    0.00019   0.00080      ok    -76.3%   1.597 -> 0.088 (0.0)
// dots_purple_354x352        0.05  0.00017    0.00016   0.00082      ok    -80.2%   0.911 -> 0.007 (0.0)
// drawn_dots_512             0.24  0.00625    0.00625   0.00620      LOSS   +0.9%   1.201 -> 0.719 (87.0)
// fabric_brown_256           0.19  0.00043    0.00043   0.00045      ok     -5.3%   1.121 -> 0.697 (20.4)
// grass_gray_512             0.24  0.00743    0.00740   0.00781      ok     -5.2%   0.891 -> 0.531 (49.7)
// gravel_gray_512            0.20  0.00417    0.00417   0.00411      LOSS   +1.4%   1.255 -> 0.658 (39.4)
// ink_a_400                  0.16  0.00343    0.00287   0.00289      ok     -0.6%   1.511 -> 0.326 (81.3)
// ink_b_400                  0.19  0.00260    0.00262   0.00809      ok    -67.7%   0.845 -> 0.155 (15.9)
// leather_64                 0.19  0.00046    0.00047   0.00136      ok    -65.4%   1.098 -> 0.814 (117.2)
// pebbles_256                0.18  0.01151    0.01164   0.01293      ok    -10.0%   0.864 -> 0.679 (126.4)
// red_checked_384            0.23  0.00041    0.00038   0.00041      ok     -7.1%   0.282 -> 0.077 (12.9)
// reptile_skin_512           0.17  0.00144    0.00139   0.00142      ok     -2.5%   0.815 -> 0.501 (58.8)
// rock_512                   0.43  0.00221    0.00219   0.00220      ok     -0.9%   0.878 -> 0.654 (45.6)
// stripes_blue_white_256     0.03  0.00000    0.00000   0.00063      ok   -100.0%   0.000 -> 0.000 (0.0)
// teddy_fur_256              0.16  0.00101    0.00096   0.00119      ok    -18.8%   1.092 -> 0.665 (13.4)
// tree_bark_512              0.31  0.00932    0.00932   0.01029      ok     -9.4%   0.949 -> 0.680 (133.8)
// water_caustics_300         0.16  0.00104    0.00100   0.00110      ok     -9.5%   1.739 -> 0.259 (40.5)
// wood_512                   0.42  0.00031    0.00031   0.00034      ok     -7.9%   0.656 -> 0.515 (23.9)
// woven_tissue_512           0.24  0.00290    0.00290   0.00282      LOSS   +2.7%   0.514 -> 0.424 (23.1)
// Fresh G'MIC sampling on the 7 textures closest to the line (this benchmark,
// GMIC_RUNS 3, 10:09-10:21, load average 7-9): ours / G'MIC median [its 3 runs]
//   drawn_dots_512    0.006253 / 0.006150 [0.00627 0.00591 0.00615]  LOSS +1.7%
//   gravel_gray_512   0.004170 / 0.004337 [0.00403 0.00435 0.00434]  ok
//   ink_a_400         0.002869 / 0.003177 [0.00602 0.00318 0.00308]  ok
//   red_checked_384   0.000383 / 0.000382 [0.00041 0.00038 0.00038]  LOSS +0.3%
//   reptile_skin_512  0.001389 / 0.001401 [0.00144 0.00140 0.00135]  ok
//   rock_512          0.002186 / 0.002142 [0.00214 0.00223 0.00210]  LOSS +2.1%
//   woven_tissue_512  0.002897 / 0.002961 [0.00296 0.00297 0.00289]  ok
// 4/7 here (gravel and woven flip to ok, rock and red_checked to loss): with
// the other 22 at their margins above (all >= 5% except bricks_with_hole
// -1.1%), 26/29 again; at this distance the verdict follows G'MIC's draw.
// CPU ours/G'MIC over the 7: 0.30 (each G'MIC run includes its process start).
//
// Session 5 (2026-11-22 12:40-13:05, issue 3 G2, tile mode only: 29 tiles in
// 21.9 s wall / 13.8 s user + 1.0 s sys, load average 5-7 on 2 cores).
// The synthesis code is unchanged since session 4 (tiles and 256 outputs are
// the same bytes: fabric_brown 0.00043, ink_a 0.002869 re-measured); new
// roll-independent figures (texture/wrap_seam_ratio.h):
//   sm cut / sm worst = source-matched ratio (jump across a pair over the
//     exemplar's own jump at the same sources; 1 = verbatim) of the synthesis
//     cut's wrap lines / of the worst line of the torus;
//   worst = worst_line_ratio (jump-based, any line, per orientation);
//   col, row = the tile's worst column / row line against the exemplar's
//     (median over 5 tile-sized windows, interior lines);
//   pct = percentile of the synthesis cut's column / row line among the lines;
//   P>1.3 = fraction of the 128 x 128 rolls whose wrap-seam ratio is > 1.3.
// Summary: wrap-seam ratio <= 1.3 at the synthesis cut 26/29 (dots_large
// 1.597, ink_a 1.511, water_caustics 1.739; unchanged), rolled 29/29;
// expected count above 1.3 at a uniformly drawn cut (sum of P>1.3) 2.68 vs
// 3 observed. Source-matched ratio at the synthesis cut 0.991-1.075 on 29/29
// (the three: 1.000, 1.075, 1.029): no wrap carries a seam. Over seeds 1-6
// (174 tiles) the synthesis cut ranks at percentile 0.480 +- 0.022 among the
// torus lines (columns and rows alike; uniform 0.5): it is an ordinary line,
// and the 3 failures are draws from the textures' own line spread.
// Worst-line ratio (jump) <= 1.3 on 0/29: not reachable, tile-sized windows
// of the exemplars reach 1.32-31.3 (median 1.78) themselves. Source-matched
// worst line <= 1.3 on 22/29; above: wood 3.18 (a visible straight seam on
// column line 86 of the synthesised tile, 57 seam pairs of 128), ink_b 6.00
// (row line 16, 75 seam pairs; faint: the texture spans 9-14 of 255 levels
// per channel, the seam shows at 18x contrast), ink_a 2.23,
// brick_gray 1.72, water_caustics 1.70, bricks_with_hole 1.39, gravel 1.32.
// Summed seam cost 2145.3 (unchanged).
// Tried, not kept (seed 1, 29 textures, bench driver outside the repo):
// Kwatra's gradient-normalised cost (eq. 5) for tiles: source-matched worst
// <= 1.3 on 24/29 (wood 3.18 -> 1.51, ink_b 6.00 -> 2.06, ink_a 2.23 -> 1.71,
// water 1.70 -> 1.42), wrap-seam ratio at the cut <= 1.3 on 27/29, but the
// eq.-1 seam cost summed 2145 -> 3364 (+57%). One or two extra refinement
// passes whose error map is the excess jump (jump minus the exemplar's jump
// at the same sources) under the same never-raise-the-seam-cost rule: wood
// unchanged, ink_b 6.00 -> 5.83, water 1.70 -> 1.62, brick_gray 1.72 -> 1.45,
// while the jump wrap ratio at the cut moved as a draw (bricks_with_hole
// 1.145 -> 1.751): the straight seams are eq.-1 optimal, so a cut that keeps
// eq. 1 keeps them.
//   texture                 ratio cut -> rolled  sm cut sm worst  worst  col tile/ex  row tile/ex  pct cut    P>1.3  seam
// box_tree_leaves_256        1.110 -> 0.705  1.000  1.131    1.43   1.43/ 1.44   1.35/ 1.37  0.61 0.87  0.002  181.1
// brick_gray_512             0.903 -> 0.169  0.999  1.721    5.46   5.46/ 3.54   4.95/ 5.20  0.69 0.61  0.300   15.5
// brick_small_96             0.886 -> 0.532  1.001  1.201    3.49   1.79/ 1.83   3.49/ 2.98  0.69 0.19  0.105  255.0
// bricks_with_hole_rgba_350  1.145 -> 0.349  1.002  1.392    3.00   2.15/ 2.46   3.00/ 3.30  0.15 0.76  0.244  119.6
// burlap_96                  0.960 -> 0.415  1.000  1.182    1.77   1.77/ 1.71   1.54/ 1.53  0.47 0.49  0.065  165.5
// cane_weave_rgba_128        0.291 -> 0.173  1.026  1.078    4.85   4.76/ 5.41   4.85/ 5.31  0.01 0.21  0.210   23.7
// chainmail_512              1.204 -> 0.387  0.995  1.186    1.87   1.76/ 1.80   1.87/ 2.00  0.94 0.35  0.060   79.9
// coffee_beans_64            1.056 -> 0.723  1.000  1.096    1.40   1.40/ 1.74   1.40/ 1.43  0.90 0.38  0.002  173.2
// cracked_mud_100            1.029 -> 0.666  1.005  1.124    1.79   1.79/ 1.61   1.44/ 1.69  0.51 0.73  0.029  150.7
// denim_256                  1.060 -> 0.746  1.000  1.096    1.43   1.43/ 1.42   1.23/ 1.20  0.39 0.99  0.000   91.9
// dots_large_208x168         1.597 -> 0.088  1.000  1.000    2.86   2.53/ 3.64   2.86/ 3.79  0.37 0.98  0.215    0.0
// dots_purple_354x352        0.911 -> 0.007  1.000  1.000    2.99   2.59/ 6.57   2.99/ 4.85  0.04 0.86  0.240    0.0
// drawn_dots_512             1.201 -> 0.719  1.000  1.098    1.40   1.40/ 1.37   1.34/ 1.43  0.99 0.76  0.001   87.0
// fabric_brown_256           1.121 -> 0.697  1.000  1.117    1.45   1.45/ 1.43   1.44/ 1.46  0.73 0.78  0.005   20.4
// grass_gray_512             0.891 -> 0.531  0.999  1.137    1.57   1.50/ 1.40   1.57/ 1.42  0.08 0.72  0.013   49.7
// gravel_gray_512            1.255 -> 0.658  1.000  1.324    1.62   1.45/ 1.68   1.62/ 1.67  0.96 0.92  0.013   39.4
// ink_a_400                  1.511 -> 0.326  1.075  2.225    3.44   2.25/ 2.42   3.44/ 2.52  0.66 0.92  0.172   81.3
// ink_b_400                  0.845 -> 0.155  1.003  5.999    4.93   2.51/ 2.07   4.93/ 2.48  0.27 0.59  0.188   15.9
// leather_64                 1.098 -> 0.814  1.001  1.044    1.38   1.26/ 1.32   1.38/ 1.29  0.96 0.78  0.000  117.2
// pebbles_256                0.864 -> 0.679  1.000  1.058    1.57   1.46/ 1.46   1.57/ 1.41  0.23 0.17  0.008  126.4
// red_checked_384            0.282 -> 0.077  1.000  1.171    2.47   2.47/ 2.45   2.39/ 2.37  0.13 0.27  0.274   12.9
// reptile_skin_512           0.815 -> 0.501  0.991  1.238    1.85   1.79/ 1.86   1.85/ 1.67  0.14 0.43  0.083   58.8
// rock_512                   0.878 -> 0.654  0.999  1.094    1.57   1.48/ 1.52   1.57/ 1.40  0.15 0.28  0.009   45.6
// stripes_blue_white_256     0.000 -> 0.000  1.000  1.000   31.84  31.84/31.33   1.00/ 1.00  0.00 0.00  0.031    0.0
// teddy_fur_256              1.092 -> 0.665  1.000  1.059    1.60   1.60/ 1.55   1.39/ 1.40  0.67 0.76  0.005   13.4
// tree_bark_512              0.949 -> 0.680  1.003  1.086    1.44   1.44/ 1.49   1.37/ 1.40  0.11 0.87  0.002  133.8
// water_caustics_300         1.739 -> 0.259  1.029  1.702    3.53   3.53/ 2.63   2.56/ 3.44  0.82 0.98  0.211   40.5
// wood_512                   0.656 -> 0.515  1.000  3.180    3.20   2.87/ 2.50   3.20/ 2.37  0.37 0.06  0.125   23.9
// woven_tissue_512           0.514 -> 0.424  1.011  1.168    1.66   1.66/ 1.73   1.62/ 1.73  0.03 0.06  0.071   23.1
//
// Session 5, straight seams (2026-11-22 13:23-13:24, tile mode, 29 tiles,
// 128 px, seed 1: 30.3 s wall / 14.2 s user + 0.8 s sys, load average 7.0-8.6
// on 2 cores; the session-5 run above: 14.0 s CPU by the tiles' own timers,
// 14.3 s now; the 7 repaired tiles 4.6 -> 6.0 CPU s). GraphcutOptions::
// straight_seam_steps (TileOptions default 32, tolerance 1.0): targeted
// repair patches on the lines whose source-matched ratio exceeds 1.3
// (texture/graphcut_synthesis.h). Only the 7 tiles holding such a line
// change (* below); the 22 others and the non-periodic 256 outputs are the
// same bytes (wood_512 and ink_a_400 graph-cut PNGs compared with cmp
// against the pre-change binary).
// Summary: source-matched worst line <= 1.3 on 28/29 (before 22/29; ink_b
// 6.00 -> 1.62 left above); summed eq.-1 seam cost 2145.3 -> 2277.5
// (+6.2%; the 7 repaired tiles 336.1 -> 468.2); wrap-seam ratio <= 1.3 at
// the synthesis cut 27/29 (before 26/29: ink_a 1.511 -> 1.252, water
// 1.739 -> 1.630, dots_large 1.597 unchanged), rolled 29/29 (the highest
// rolled value among the 7: 0.520, before 0.515); source-matched ratio at
// the synthesis cut 0.962-1.125 (before 0.991-1.075: ink_a 1.075 -> 1.125).
// Seen (2x2 repeats, 3x enlarged): wood's straight vertical seam through the
// whole tile is gone; what remains are short staggered vertical grain
// breaks (the repair patches' own seams, each a quarter of the tile long),
// visible on close look -- a horizontally grained wood shows any vertical
// seam. ink_b (contrast stretched 18x): the straight horizontal band edge
// is broken up.
// Tried, not kept (the 7 tiles, cost = summed eq.-1 seam cost of the 7):
// tolerance 0.1 / 0.3 / 0.6 (first version: 4 candidates, lowest penalty,
// rectangular band, eq.-5 cut): wood 2.24 / 1.98 / 1.39, tiles fixed
// 1 / 2 / 3 of 7; choosing (8 candidates, tolerance 0.6) the lowest penalty
// instead of the most penalty removed per unit of cost added: 3 vs 5 of 7
// at the same cost (472); the repair cut with eq. 1 instead of eq. 5
// (tolerance 1.0): 3/7 at 419.8 vs 6/7 at 482.7 (eq. 1: ink_b 2.06, water
// 1.39, wood 1.30); the lens-shaped forced band against a rectangle: 6/7 at
// 468.2 vs 6/7 at 482.7, lower ratios (wood 1.28 vs 1.30, brick_gray 1.22 vs
// 1.30); 64 steps instead of 32 (rectangle): ink_b 1.63 -> 1.53 only (each
// repair of its faint texture -- 9-14 levels per channel -- makes new lines
// above 1.3); repair patch a third / a sixth of the tile instead of a
// quarter: 6/7 at 536.9 / 6/7 at 401.5, but wrap ratio at the cut <= 1.3 on
// 5/7 (ink_a 1.50 / 1.48) instead of 6/7. A sixth is the cheaper choice if
// the seam cost matters more than the cut figure.
//   texture                    sm worst before -> after  seam before -> after  ratio cut -> rolled (after)  sm cut
// box_tree_leaves_256        1.131 -> 1.131          181.1 ->  181.1       1.110 -> 0.705            1.000
// brick_gray_512             1.721 -> 1.222           15.5 ->   25.2       0.823 -> 0.164            0.962  *
// brick_small_96             1.201 -> 1.201          255.0 ->  255.0       0.886 -> 0.532            1.001
// bricks_with_hole_rgba_350  1.392 -> 1.230          119.6 ->  145.3       1.149 -> 0.344            1.002  *
// burlap_96                  1.182 -> 1.182          165.5 ->  165.5       0.960 -> 0.415            1.000
// cane_weave_rgba_128        1.078 -> 1.078           23.7 ->   23.7       0.291 -> 0.173            1.026
// chainmail_512              1.186 -> 1.186           79.9 ->   79.9       1.204 -> 0.387            0.995
// coffee_beans_64            1.096 -> 1.096          173.2 ->  173.2       1.056 -> 0.723            1.000
// cracked_mud_100            1.124 -> 1.124          150.7 ->  150.7       1.029 -> 0.666            1.005
// denim_256                  1.096 -> 1.096           91.9 ->   91.9       1.060 -> 0.746            1.000
// dots_large_208x168         1.000 -> 1.000            0.0 ->    0.0       1.597 -> 0.088            1.000
// dots_purple_354x352        1.000 -> 1.000            0.0 ->    0.0       0.911 -> 0.007            1.000
// drawn_dots_512             1.098 -> 1.098           87.0 ->   87.0       1.201 -> 0.719            1.000
// fabric_brown_256           1.117 -> 1.117           20.4 ->   20.4       1.121 -> 0.697            1.000
// grass_gray_512             1.137 -> 1.137           49.7 ->   49.7       0.891 -> 0.531            0.999
// gravel_gray_512            1.324 -> 1.124           39.4 ->   43.1       1.257 -> 0.660            1.000  *
// ink_a_400                  2.225 -> 1.272           81.3 ->  128.2       1.252 -> 0.342            1.125  *
// ink_b_400                  5.999 -> 1.618           15.9 ->   24.5       0.847 -> 0.197            1.018  *
// leather_64                 1.044 -> 1.044          117.2 ->  117.2       1.098 -> 0.814            1.001
// pebbles_256                1.058 -> 1.058          126.4 ->  126.4       0.864 -> 0.679            1.000
// red_checked_384            1.171 -> 1.171           12.9 ->   12.9       0.282 -> 0.077            1.000
// reptile_skin_512           1.238 -> 1.238           58.8 ->   58.8       0.815 -> 0.501            0.991
// rock_512                   1.094 -> 1.094           45.6 ->   45.6       0.878 -> 0.654            0.999
// stripes_blue_white_256     1.000 -> 1.000            0.0 ->    0.0       0.000 -> 0.000            1.000
// teddy_fur_256              1.059 -> 1.059           13.4 ->   13.4       1.092 -> 0.665            1.000
// tree_bark_512              1.086 -> 1.086          133.8 ->  133.8       0.949 -> 0.680            1.003
// water_caustics_300         1.702 -> 1.238           40.5 ->   56.4       1.630 -> 0.278            1.028  *
// wood_512                   3.180 -> 1.276           23.9 ->   45.5       0.647 -> 0.520            1.000  *
// woven_tissue_512           1.168 -> 1.168           23.1 ->   23.1       0.514 -> 0.424            1.011

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/bidirectional_similarity.h"
#include "texture/graphcut_synthesis.h"
#include "texture/tileable_tile.h"
#include "texture/wrap_seam_ratio.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

// The one similarity setting of this benchmark (see the header comment).
BidirectionalResult bidirectional(const Image& out, const Image& ex) {
  BidirectionalOptions o;
  o.patch = 7;
  o.stride = 2;
  o.max_candidates = 0;  // exact
  return bidirectional_similarity(out, ex, o);
}

// G'MIC may write a different channel count (e.g. drops or adds alpha): match the exemplar.
Image match_channels(const Image& img, int channels) {
  if (img.channels == channels) return img;
  Image r(img.width, img.height, channels, 1.f);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < channels; ++c) {
        const int sc = img.channels == 1 ? 0 : std::min(c, img.channels - 1);
        r.at(x, y, c) = (c == 3 && img.channels < 4) ? 1.f : img.at(x, y, sc);
      }
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double children_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_CHILDREN, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}
double self_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// Reference for a tile's worst-line ratio: the median, over 5 windows of the
// exemplar of the tile's size (4 corners and centre; the whole exemplar if
// smaller), of the worst interior line of the window (line_jump_profile,
// non-periodic): how uneven the lines of a seamless piece of the texture are.
// Returns {worst line, worst column line, worst row line}, each such a median.
std::vector<double> exemplar_worst_line_ratio(const Image& ex, int size) {
  const int w = std::min(size, ex.width), h = std::min(size, ex.height);
  std::vector<double> v, vc, vr;
  const int xs[5] = {0, ex.width - w, 0, ex.width - w, (ex.width - w) / 2};
  const int ys[5] = {0, 0, ex.height - h, ex.height - h, (ex.height - h) / 2};
  for (int k = 0; k < 5; ++k) {
    Image c(w, h, ex.channels);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int ch = 0; ch < ex.channels; ++ch) c.at(x, y, ch) = ex.at(xs[k] + x, ys[k] + y, ch);
    const LineJumpProfile p = line_jump_profile(c, false);
    v.push_back(p.worst_ratio);
    vc.push_back(p.worst_column_ratio);
    vr.push_back(p.worst_row_ratio);
  }
  return {median(v), median(vc), median(vr)};
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : std::string(SURFTEX_SHARED_DATA_DIR) + "/textures";
  const std::string work = argc > 2 ? argv[2] : "/tmp/surftex_bench_graphcut";
  fs::create_directories(work);
  const bool have_gmic = std::system("command -v gmic >/dev/null 2>&1") == 0;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".png") {
      if (argc > 3 && std::string(argv[3]) != "-" && ("," + std::string(argv[3]) + ",").find("," + e.path().stem().string() + ",") ==
                          std::string::npos)
        continue;
      files.push_back(e.path().string());
    }
  std::sort(files.begin(), files.end());

  // G'MIC's syntexturize_matchpatch is unseeded: its output (and score) moves
  // between runs, so it runs `gmic_runs` times and we compare with the median.
  const int gmic_runs = argc > 4 ? std::max(0, std::atoi(argv[4])) : 3;
  const int tile_size = argc > 5 ? std::max(8, std::atoi(argv[5])) : 128;
  const std::string mode = argc > 6 ? argv[6] : "all";
  TileOptions tile_options;
  if (argc > 7) tile_options.straight_seam_steps = std::max(0, std::atoi(argv[7]));
  if (argc > 8) tile_options.straight_seam_cost_tolerance = std::max(0.0, std::atof(argv[8]));
  if (mode != "all" && mode != "synthesis" && mode != "tile") {
    std::fprintf(stderr, "bench_graphcut: MODE must be all, synthesis or tile, got '%s'\n", mode.c_str());
    return 2;
  }
  const bool run_synthesis = mode != "tile", run_tile = mode != "synthesis";

  int compared = 0, no_worse = 0, faster = 0, tiles_ok = 0, tiles_ok_synthesis_cut = 0, tiles_worst_ok = 0, tiles_sm_worst_ok = 0;
  double expected_fail = 0, seam_total = 0;
  double t_ours = 0, t_gmic = 0, cpu_ours = 0, cpu_gmic = 0;
  for (const auto& f : files) {
    const std::string name = fs::path(f).stem().string();
    Image ex = read_image(f);
    nlohmann::json j;
    j["texture"] = name;
    j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height) + "x" + std::to_string(ex.channels);

    if (run_synthesis) {
      GraphcutOptions o;
      o.seed = 1;
      double c0 = self_cpu_seconds();
      Timer tm;
      GraphcutResult r = graphcut_synthesize_detailed(ex, 256, 256, o);
      const double ours_s = tm.seconds(), ours_cpu = self_cpu_seconds() - c0;
      const std::string ours_png = work + "/" + name + "_graphcut.png";
      write_image(ours_png, r.image);
      BidirectionalResult bo = bidirectional(r.image, ex);
      j["surftex_seconds"] = ours_s;
      j["surftex_cpu_seconds"] = ours_cpu;
      j["surftex_bds"] = bo.total;
      j["surftex_coherence"] = bo.coherence;
      j["surftex_completeness"] = bo.completeness;
      j["surftex_seam_cost"] = {r.seam_cost_after_fill, r.seam_cost_final};
      j["surftex_patches"] = {r.fill_patches, r.refinement_tried, r.refinement_accepted};

      if (have_gmic && gmic_runs > 0) {
        std::vector<double> walls, cpus, scores;
        int failed_rc = 0;
        for (int run = 0; run < gmic_runs; ++run) {
          const std::string gm_png = work + "/" + name + "_gmic" + std::to_string(run) + ".png";
          fs::remove(gm_png);
          const std::string cmd = "gmic -v -1 input '" + f + "' syntexturize_matchpatch 256,256 output '" +
                                  gm_png + "' >/dev/null 2>&1";
          double g0 = children_cpu_seconds();
          tm.reset();
          int rc = std::system(cmd.c_str());
          const double gm_s = tm.seconds(), gm_cpu = children_cpu_seconds() - g0;
          if (rc != 0 || !fs::exists(gm_png)) {
            failed_rc = rc != 0 ? rc : -1;
            continue;
          }
          Image g = match_channels(read_image(gm_png), ex.channels);
          walls.push_back(gm_s);
          cpus.push_back(gm_cpu);
          scores.push_back(bidirectional(g, ex).total);
        }
        if (!scores.empty()) {
          const double gm_bds = median(scores), gm_s = median(walls), gm_cpu = median(cpus);
          j["gmic_runs"] = scores.size();
          j["gmic_seconds_all"] = walls;
          j["gmic_cpu_seconds_all"] = cpus;
          j["gmic_bds_all"] = scores;
          j["gmic_seconds"] = gm_s;
          j["gmic_cpu_seconds"] = gm_cpu;
          j["gmic_bds"] = gm_bds;
          j["surftex_no_worse"] = bo.total <= gm_bds;
          j["surftex_faster_wall"] = ours_s <= gm_s;
          j["surftex_faster_cpu"] = ours_cpu <= gm_cpu;
          ++compared;
          if (bo.total <= gm_bds) ++no_worse;
          if (ours_cpu <= gm_cpu) ++faster;
          t_ours += ours_s;
          t_gmic += gm_s;
          cpu_ours += ours_cpu;
          cpu_gmic += gm_cpu;
        }
        if (failed_rc != 0) j["gmic_error"] = failed_rc;
      }
    }  // run_synthesis

    if (run_tile) {
      const TileOptions& to = tile_options;
      double c0 = self_cpu_seconds();
      Timer tm;
      TileResult t = make_tileable_detailed(ex, tile_size, to);
      j["tile_size"] = tile_size;
      j["tile_seconds"] = tm.seconds();
      j["tile_cpu_seconds"] = self_cpu_seconds() - c0;
      j["tile_wrap_seam_ratio"] = t.wrap_seam_ratio;
      j["tile_wrap_seam_ratio_at_synthesis_cut"] = t.wrap_seam_ratio_at_synthesis_cut;
      j["tile_cut_shift"] = {t.shift_x, t.shift_y};
      j["tile_seam_cost"] = t.seam_cost;
      // Roll-independent figures: the worst line of the torus, and the
      // distribution of the wrap-seam ratio over all size x size rolls (the
      // synthesis cut is one draw from it if no line is special).
      const LineJumpProfile prof = line_jump_profile(t.tile, true);
      std::vector<double> rolls;
      rolls.reserve(static_cast<std::size_t>(tile_size) * tile_size);
      for (int ry = 0; ry < tile_size; ++ry)
        for (int rx = 0; rx < tile_size; ++rx) rolls.push_back(rolled_wrap_seam_ratio(prof, rx, ry));
      const double above = static_cast<double>(std::count_if(rolls.begin(), rolls.end(), [](double v) { return v > 1.3; })) /
                           static_cast<double>(rolls.size());
      j["tile_worst_line_ratio"] = t.worst_line_ratio;
      j["tile_worst_line"] = {prof.worst_is_column ? "column" : "row", prof.worst_index};  // in the rolled tile
      j["tile_worst_column_row_ratio"] = {prof.worst_column_ratio, prof.worst_row_ratio};
      j["tile_source_matched_wrap_ratio_at_synthesis_cut"] = t.source_matched_wrap_ratio_at_synthesis_cut;
      j["tile_source_matched_worst_line_ratio"] = t.source_matched_worst_line_ratio;
      j["tile_synthesis_cut_percentile"] = {t.synthesis_column_percentile, t.synthesis_row_percentile};
      j["tile_roll_wrap_ratio_median"] = median(rolls);
      j["tile_roll_wrap_ratio_fraction_above_1_3"] = above;
      const std::vector<double> exw = exemplar_worst_line_ratio(ex, tile_size);
      j["exemplar_worst_line_ratio"] = exw[0];
      j["exemplar_worst_column_row_ratio"] = {exw[1], exw[2]};
      expected_fail += above;
      seam_total += t.seam_cost;
      if (t.worst_line_ratio <= 1.3) ++tiles_worst_ok;
      if (t.source_matched_worst_line_ratio <= 1.3) ++tiles_sm_worst_ok;
      const WrapSeamStats ws = wrap_seam_stats(t.tile);
      j["tile_wrap_mean_jump"] = ws.wrap_mean;
      j["tile_inside_mean_jump"] = ws.inside_mean;
      j["exemplar_wrap_seam_ratio"] = wrap_seam_ratio(ex);
      if (t.wrap_seam_ratio <= 1.3) ++tiles_ok;
      if (t.wrap_seam_ratio_at_synthesis_cut <= 1.3) ++tiles_ok_synthesis_cut;
      Image rep(2 * tile_size, 2 * tile_size, t.tile.channels);
      for (int y = 0; y < rep.height; ++y)
        for (int x = 0; x < rep.width; ++x)
          for (int c = 0; c < rep.channels; ++c) rep.at(x, y, c) = t.tile.at(x % tile_size, y % tile_size, c);
      write_image(work + "/" + name + "_tile2x2.png", rep);
    }  // run_tile
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
  }
  nlohmann::json s;
  s["summary"] = true;
  s["textures"] = files.size();
  s["gmic_available"] = have_gmic;
  s["compared"] = compared;
  s["gmic_runs_per_texture"] = gmic_runs;
  s["no_worse_bds_than_gmic_median"] = no_worse;
  s["fraction_no_worse_bds"] = compared ? static_cast<double>(no_worse) / compared : 0.0;
  s["surftex_cpu_no_slower"] = faster;
  s["wall_time_ratio_surftex_over_gmic"] = t_gmic > 0 ? t_ours / t_gmic : 0.0;
  s["cpu_time_ratio_surftex_over_gmic"] = cpu_gmic > 0 ? cpu_ours / cpu_gmic : 0.0;
  s["surftex_total_seconds"] = t_ours;
  s["gmic_total_seconds"] = t_gmic;
  s["tile_size"] = tile_size;
  s["tiles_wrap_seam_ratio_le_1_3"] = tiles_ok;
  s["tiles_wrap_seam_ratio_at_synthesis_cut_le_1_3"] = tiles_ok_synthesis_cut;
  s["tiles_worst_line_ratio_le_1_3"] = tiles_worst_ok;
  s["tiles_source_matched_worst_line_ratio_le_1_3"] = tiles_sm_worst_ok;
  s["tiles_expected_wrap_ratio_above_1_3_at_a_random_cut"] = expected_fail;
  s["tiles_seam_cost_sum"] = seam_total;
  std::printf("%s\n", s.dump().c_str());
  return 0;
}
