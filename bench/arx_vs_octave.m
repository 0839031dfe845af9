% ARX(3,3,1) with Octave's control package on the data file given as argument
% (columns u, y with a header line, Ts = 0.01 s). Prints the best of 3 runs.
% Used by bench/arx_vs_octave.sh.
pkg load control
args = argv();
d = dlmread(args{1}, ',', 1, 0);
u = d(:, 1); y = d(:, 2);
dat = iddata(y, u, 0.01);
best = inf;
for k = 1:3
  t0 = tic;
  % Octave's control package counts nk from one sample of delay: its nk = 0
  % gives B = b1 q^-1 + b2 q^-2 + b3 q^-3, i.e. pneumid's (and MATLAB's) nk = 1
  % (checked: both programs then return the same coefficients).
  sys = arx(dat, 'na', 3, 'nb', 3, 'nk', 0);
  best = min(best, toc(t0));
end
[num, den] = filtdata(sys);
printf('octave_seconds %.6f\n', best);
printf('octave_a %s\n', num2str(den{1}, '%.5f '));
printf('octave_b %s\n', num2str(num{1}, '%.5f '));
