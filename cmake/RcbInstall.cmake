# Install rules: headers, libraries, rcb::rcb export, rcbConfig.cmake, rcb.pc.
# (Completed in the build/install task.)
