//! G-code dialects (LinuxCNC, Fanuc, Sinumerik 840D, Heidenhain) and APT CLDATA read/write.
