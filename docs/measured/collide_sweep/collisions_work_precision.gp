set terminal pngcairo size 1500,520 font 'DejaVu Sans,10' noenhanced
set output 'docs/measured/collide_sweep/collisions_work_precision.png'
set multiplot layout 1,3 title 'Contacts, work-precision: ms/step against deepest overlap at the end (Stepwise solid, Box2D 2.4.1 dashed; labels: substeps x iterations)'
set logscale xy
set grid
set xlabel 'ms per step'
set ylabel 'deepest overlap (mm)'
set key top right font ',8'
set title 'pile'
plot 'docs/measured/collide_sweep/collisions_sweep.dat' index 0 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 0 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 1 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 1 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set title 'pyramid'
plot 'docs/measured/collide_sweep/collisions_sweep.dat' index 2 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 2 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 3 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 3 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
set title 'rain'
plot 'docs/measured/collide_sweep/collisions_sweep.dat' index 4 using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index 4 using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index 5 using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index 5 using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle
unset multiplot
