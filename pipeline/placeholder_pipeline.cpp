// Placeholder so the pipeline library has a source until its first real one lands; delete then.
