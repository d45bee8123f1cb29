"""C sources of the FlexJoint FMU runtime, shipped as package data and compiled on first export."""
