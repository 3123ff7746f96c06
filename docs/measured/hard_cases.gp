set terminal pngcairo size 1800,1900 font 'DejaVu Sans,10' noenhanced
set output 'docs/measured/hard_cases.png'
set multiplot layout 5,4 title 'Hard cases: error against median ms/step (Stepwise fixed substeps x 1 iteration: solid, labels = substeps; Stepwise defaults: square; Box2D 2.4.1, 8+3 iterations: dashed). Sweeps: worst error, slowest step'
set grid
set logscale x
set format x '%g'
set format y '%g'
set xlabel 'ms per step'
set key top right font ',8'
set logscale y
set ylabel '|rolling speed - (-w0 r/3)|, m/s'
set title 'disc spun onto the floor'
plot 'docs/measured/hard_cases.dat' index 0 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 0 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 1 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 2 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 2 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'sinkage below the box top, m'
set title 'ball on a 2 cm box'
plot 'docs/measured/hard_cases.dat' index 3 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 3 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 4 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 5 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 5 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'widest joint opening, m'
set title '1000 kg on ten 1 kg links'
plot 'docs/measured/hard_cases.dat' index 6 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 6 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 7 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 8 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 8 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'widest joint opening / link length'
set title 'chain of 20 links'
plot 'docs/measured/hard_cases.dat' index 9 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 9 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 10 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 11 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 11 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel '|crate velocity - its motion over the last step / dt|, m/s'
set title 'crate on a bridge: velocity against motion'
plot 'docs/measured/hard_cases.dat' index 12 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 12 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 13 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 14 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 14 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'sinkage of the top box, m'
set title 'stack of 10 boxes'
plot 'docs/measured/hard_cases.dat' index 15 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 15 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 16 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 17 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 17 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'push-out: fastest speed relative to free fall in flight, m/s'
set title 'crowd of 64 at one point'
plot 'docs/measured/hard_cases.dat' index 18 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 18 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 19 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 20 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 20 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'push-out: fastest speed relative to free fall in flight, m/s'
set title 'crowd of 1000 at one point'
plot 'docs/measured/hard_cases.dat' index 21 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 21 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 22 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 23 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 23 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'push-out: fastest speed relative to free fall in flight, m/s'
set title 'crowd of 10000 at one point'
plot 'docs/measured/hard_cases.dat' index 24 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 24 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 25 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 26 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 26 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'deepest floor sinkage, m'
set title '300-ball pile'
plot 'docs/measured/hard_cases.dat' index 27 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 27 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 28 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 29 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 29 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'widest joint opening, m'
set title 'box2d joint_grid'
plot 'docs/measured/hard_cases.dat' index 30 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 30 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 31 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 32 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 32 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'top box sideways drift, m'
set title 'box2d large_pyramid'
plot 'docs/measured/hard_cases.dat' index 33 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 33 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 34 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 35 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 35 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'top box sideways drift, m'
set title 'box2d many_pyramids'
plot 'docs/measured/hard_cases.dat' index 36 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 36 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 37 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 38 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 38 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'deepest contact overlap, m'
set title 'box2d rain'
plot 'docs/measured/hard_cases.dat' index 39 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 39 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 40 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 41 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 41 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'deepest contact overlap, m'
set title 'box2d smash'
plot 'docs/measured/hard_cases.dat' index 42 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 42 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 43 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 44 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 44 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set logscale y
set ylabel 'deepest contact overlap, m'
set title 'box2d spinner'
plot 'docs/measured/hard_cases.dat' index 45 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 45 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 46 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 47 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 47 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
unset logscale y
set ylabel 'bodies escaped'
set title 'box2d tumbler'
plot 'docs/measured/hard_cases.dat' index 48 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 48 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 49 using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index 50 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 50 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
unset multiplot
