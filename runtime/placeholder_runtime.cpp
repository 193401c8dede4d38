// Placeholder so the runtime library has a source until its first real one lands; delete then.
