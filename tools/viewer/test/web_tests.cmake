# node-driven tests: filled below
