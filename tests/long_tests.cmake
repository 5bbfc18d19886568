# The longest tests, started first: ctest -j starts tests by COST, highest first, and a build that
# has no timings of its own yet (CI's, every time) otherwise starts them in declaration order, so
# that a long test declared late ran on alone at the end (docs/FUZZING.md, "CI time"). COST is in
# seconds: under ASan/UBSan (CI's sanitizer build) for the tests that build runs, in the Release
# build for the others; a renamed test only loses its place (set_tests_properties here ignores
# names that no test has). Included by ctest after the discovered tests (tests/CMakeLists.txt).
set_tests_properties(
  ImportLeafMesh.RandomHierarchiesWithScatteredVerticesImportOrAreRefused PROPERTIES COST 367)
set_tests_properties(ImportLeafMesh.RandomHierarchiesMovedFarImportOrAreRefused PROPERTIES COST 222)
set_tests_properties(EncodeDecode.EveryWriterRefusesOrWritesWhatItsReaderReadsBack PROPERTIES COST 180)
set_tests_properties(ImportLeafMeshSharedData.FandiskGaussRemeshMovedImportsWithItsBase PROPERTIES COST 66)
set_tests_properties(SeriesGolden.PaddedFramesDecodeAndAreWhatTheWritersWrite PROPERTIES COST 28)
set_tests_properties(ImportLeafMeshSharedData.FandiskMeanRemeshUnmovedImportsWithItsBase PROPERTIES COST 26)
set_tests_properties(GoldenDecoded.EveryFileDecodesToItsCommittedHash PROPERTIES COST 24)
set_tests_properties(CraftedFiles.SeriesWriterPadsCostlessFrames PROPERTIES COST 22)
set_tests_properties(SurfaceRemeshing.KeepsItsGuarantees PROPERTIES COST 21)
set_tests_properties(CraftedFiles.OctreeWriterPadsCostlessForests PROPERTIES COST 20)
set_tests_properties(ImportMesh.SharedDataFandiskMeanRemeshFindsItsBase PROPERTIES COST 9)
set_tests_properties(HierarchyCoder.ExhaustiveSmallHierarchies PROPERTIES COST 4)
set_tests_properties(Codec.ThousandRandomHierarchiesRoundTripBitExactly PROPERTIES COST 3)
