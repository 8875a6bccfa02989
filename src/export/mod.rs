//! Outputs of an animation: JSON, CSV, glTF (.glb), GIF and PNG frames (issue 6).
