// Experiment and set-point signals, with one spec syntax shared by every
// command that takes a signal (`--input`, `--setpoint`):
//
//   step:from=A,to=B,at=T
//   staircase:levels=0 20 40 20,dwell=1.5[,at=T]       (also "multistep")
//   prbs:low=A,high=B,order=7,clock=0.05[,seed=N][,at=T]
//   prbs-levels:low=A,high=B,levels=5,clock=0.2[,seed=N][,at=T]  (multi-level PRBS)
//   chirp:from=A,to=B,f0=0.1,f1=10[,at=T][,duration=D]   (A..B amplitude range)
//   sine:from=A,to=B,frequency=F[,at=T][,duration=D]     (A..B amplitude range)
//   ramp:from=A,to=B,at=T,duration=D
//   file:PATH[,col=u][,time=t]                          (CSV or .mat; held between samples)
// Every kind also accepts min=, max= (amplitude limits) and offset=. Values of
// levels= are separated by spaces, ';' or ',' (levels=0,20,40); the grammar is
// that of common/spec.hpp.
#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

namespace pneumid {

/// An input or set-point signal of time (s), parsed from a spec (see above).
class Signal {
 public:
  virtual ~Signal() = default;
  /// Value at time t (seconds); piecewise-constant signals switch at their edges.
  virtual double operator()(double t) const = 0;
  /// The spec this signal was parsed from (normalized).
  virtual std::string ToString() const = 0;
  /// Throws InvalidArgument when the signal cannot be sampled every Ts seconds
  /// without aliasing (a chirp above the Nyquist frequency 1/(2 Ts)). Callers
  /// that sample a signal (experiments, closed loops, Sample) check it first.
  virtual void CheckSampleTime(double /*Ts*/) const {}
  /// Samples at t = t0 + k Ts, k = 0..n-1.
  /// @throws InvalidArgument for a bad Ts or n, or as CheckSampleTime.
  Eigen::VectorXd Sample(double Ts, Eigen::Index n, double t0 = 0.0) const;
};

/// Parses a signal spec (see above). Throws InvalidArgument naming the spec and
/// the offending key or value, or DataError for an unreadable file.
std::unique_ptr<Signal> ParseSignal(const std::string& spec);

/// Help text describing the syntax, for the CLI's --help.
std::string SignalSyntaxHelp();

}  // namespace pneumid
