//! Chaplygin–Appell integrals C1, C2 (NOTES §6).
