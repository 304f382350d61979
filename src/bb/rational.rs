//! The rational terms of the 2001 scheme: (Σ w_m α^μm)/(Σ α^μm) · B^n_κ(α).
