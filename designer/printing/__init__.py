"""Print-ready parts: the specimen as a mesh, the slicer settings, the 3MF plate and the runs table."""
