"""HTTP submission service for gymgrade."""
