"""The C runtime of the joint FMU: generic FMI 2 and FMI 3 layers and the FlexJoint model, shipped as data."""
