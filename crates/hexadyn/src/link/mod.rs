//! The real-time link to the robot (thesis Section 2.3.2, Figs. 2.17-2.22): the master/slave
//! UDP protocol ([`protocol`]).
pub mod protocol;
