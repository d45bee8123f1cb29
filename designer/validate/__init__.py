"""`designer validate`: the checks of every subsystem (study data, statistics, model, exports, rig
identification, co-simulation) and the report that renders them. The top of the library: it may
import every other package, and none imports it."""
