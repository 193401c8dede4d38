// Placeholder so the platform library has a source until its first real one lands; delete then.
