// Placeholder so the solver library has a source until its first real one lands; delete then.
