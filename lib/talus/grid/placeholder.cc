namespace talus { int talus_placeholder = 0; }
