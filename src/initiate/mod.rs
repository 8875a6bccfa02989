//! §6 initiation: perception (HPR, visual field), drives and actions, the simulation loop (issue 5).
