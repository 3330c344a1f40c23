"""Simulators written apart from the plant FMU, that benchmarks and tests run the toolkit on.

- :mod:`benchmarks.simulators.field_sim`: a drive's log as a field record would be, with
  effects the plant FMU leaves out (stick-slip friction, delays, load torques, encoders);
- :mod:`benchmarks.simulators.modal_link`: a flexible link from the continuous beam's modes;
- :mod:`benchmarks.simulators.fleet_sample`: a fleet of axes, with drifting ones, as log folders;
- :mod:`benchmarks.simulators.thirdparty_plant`: a chain assembled from FMUs another tool
  exported.
"""
