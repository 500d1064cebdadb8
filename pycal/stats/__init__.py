"""Statistics of a calibration: pure maths (numpy, scipy, scikit-learn, emcee).

Never imports the runner, YADE or the configs: every function takes arrays and
returns numbers, so each piece is tested on toy curves with known answers.

Modules (one idea each):
  scales     a parameter's scale (linear or log) mapped onto [0, 1]
  noise      seed noise estimated from repeated runs at the same point
  gp         the response model: a Gaussian process (scikit-learn) fitted to every run
  inversion  a 1-parameter response model inverted for a target: estimate, 95 % interval
  posterior  2-3 coupled parameters: posterior samples (emcee) over a GP surrogate
  design     the next point: the one that most shrinks the uncertainty near the target
  stopping   the stop rule: interval within tolerance, target beyond a bound, budget spent
"""
