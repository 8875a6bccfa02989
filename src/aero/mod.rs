//! §5 step 2: Hummel's power-reduction model.
