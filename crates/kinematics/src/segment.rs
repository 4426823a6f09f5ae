//! Segmentation by deviation (placeholder).
