"""The study's rig pipeline: log schema, identification, the virtual rig, and cleaning."""
