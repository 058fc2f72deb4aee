//! colour (to come)
