//! The observer interface, and the observers that combine others.

use super::Event;

/// Receives every [`Event`] of a grouping run, in order.
pub trait Observer {
    /// Called once per event.
    fn on_event(&mut self, event: &Event<'_>);

    /// Whether this observer ignores every event, so that the algorithm may skip preparing
    /// them (the partitioned schedule and pre-grouping then buffer no events of their parallel
    /// parts). Default: false.
    fn is_silent(&self) -> bool {
        false
    }
}

/// The silent observer.
impl Observer for () {
    #[inline(always)]
    fn on_event(&mut self, _: &Event<'_>) {}

    fn is_silent(&self) -> bool {
        true
    }
}

impl<O: Observer + ?Sized> Observer for &mut O {
    #[inline]
    fn on_event(&mut self, event: &Event<'_>) {
        (**self).on_event(event)
    }

    fn is_silent(&self) -> bool {
        (**self).is_silent()
    }
}

/// An optional observer (e.g. a progress bar shown only on a terminal).
impl<O: Observer> Observer for Option<O> {
    #[inline]
    fn on_event(&mut self, event: &Event<'_>) {
        if let Some(o) = self {
            o.on_event(event)
        }
    }

    fn is_silent(&self) -> bool {
        self.as_ref().is_none_or(O::is_silent)
    }
}

/// Forwards each event to two observers (e.g. a recorder and a progress bar).
pub struct Tee<A, B>(pub A, pub B);

impl<A: Observer, B: Observer> Observer for Tee<A, B> {
    #[inline]
    fn on_event(&mut self, event: &Event<'_>) {
        self.0.on_event(event);
        self.1.on_event(event);
    }

    fn is_silent(&self) -> bool {
        self.0.is_silent() && self.1.is_silent()
    }
}
