// Placeholder so the common library has a source until its first real one lands; delete then.
